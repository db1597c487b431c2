#pragma once
/// Text for XML and SVG documents: the characters that would end or break a text node or an attribute
/// value replaced by entities. Header-only and dependency-free, so that writers outside the contract
/// library (the benchmarks' plots) use the same escaping as curve.svg.
#include <string>

namespace balloon::contract {

/// `text` with &, <, > and " replaced by their entities.
inline std::string xml_escaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace balloon::contract
