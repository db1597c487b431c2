#pragma once
/// A small JSON reader for the reports the jobs write (JsonWriter's output): enough to read a stored
/// report back (fit results, the mold tube of a design) without a JSON library in the jobs layer.
#include <string>
#include <utility>
#include <vector>

#include "result.hpp"

namespace balloon::jobs {

/// One parsed JSON value.
struct JsonValue {
  enum class Kind { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;                                    ///< Bool only
  double number = 0.0;                                     ///< Number only
  std::string text;                                        ///< String only (UTF-8)
  std::vector<JsonValue> items;                            ///< Array elements in order
  std::vector<std::pair<std::string, JsonValue>> members;  ///< Object members in order

  /// The member named `key` of an object (the first one if repeated); null if absent or not an object.
  const JsonValue* find(const std::string& key) const;
};

/// Parses one JSON document (RFC 8259; nesting at most 64 deep). Fails with "not valid JSON (at byte N)"
/// or "trailing bytes after the JSON value".
Result<JsonValue> parse_json(const std::string& text);

}  // namespace balloon::jobs
