#include "jobs/json_writer.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace balloon::jobs {

std::string json_quote(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out.push_back('"');
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          static const char* hex = "0123456789abcdef";
          out += "\\u00";
          out.push_back(hex[(c >> 4) & 0xf]);
          out.push_back(hex[c & 0xf]);
        } else {
          out.push_back(c);
        }
    }
  }
  out.push_back('"');
  return out;
}

std::string json_number(double number) {
  if (!std::isfinite(number)) return "null";
  char buffer[64];
  // std::to_chars without a format gives the shortest round-trip representation.
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), number);
  if (error != std::errc()) return "null";
  return std::string(buffer, end);
}

void JsonWriter::prefix(std::string_view key) {
  if (m_first.empty()) {
    if (!m_out.empty()) throw std::logic_error("JsonWriter: a second top-level value");
    if (!key.empty()) throw std::logic_error("JsonWriter: a key at the top level");
    return;
  }
  if (!m_first.back()) m_out.push_back(',');
  m_first.back() = false;
  if (m_is_object.back()) {
    if (key.empty()) throw std::logic_error("JsonWriter: a member without a key");
    m_out += json_quote(key);
    m_out.push_back(':');
  } else if (!key.empty()) {
    throw std::logic_error("JsonWriter: a key inside an array");
  }
}

JsonWriter& JsonWriter::begin_object(std::string_view key) {
  prefix(key);
  m_out.push_back('{');
  m_first.push_back(true);
  m_is_object.push_back(true);
  return *this;
}

JsonWriter& JsonWriter::end_object() {
  if (m_is_object.empty() || !m_is_object.back()) throw std::logic_error("JsonWriter: end_object without an object");
  m_out.push_back('}');
  m_first.pop_back();
  m_is_object.pop_back();
  return *this;
}

JsonWriter& JsonWriter::begin_array(std::string_view key) {
  prefix(key);
  m_out.push_back('[');
  m_first.push_back(true);
  m_is_object.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::end_array() {
  if (m_is_object.empty() || m_is_object.back()) throw std::logic_error("JsonWriter: end_array without an array");
  m_out.push_back(']');
  m_first.pop_back();
  m_is_object.pop_back();
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view key, std::string_view text) {
  prefix(key);
  m_out += json_quote(text);
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view key, double number) {
  prefix(key);
  m_out += json_number(number);
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view key, long long number) {
  prefix(key);
  m_out += std::to_string(number);
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view key, bool flag) {
  prefix(key);
  m_out += flag ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::raw(std::string_view key, std::string_view json) {
  prefix(key);
  m_out += json;
  return *this;
}

const std::string& JsonWriter::str() const {
  if (!m_first.empty()) throw std::logic_error("JsonWriter: unclosed object or array");
  return m_out;
}

}  // namespace balloon::jobs
