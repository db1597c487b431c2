#pragma once
/// A small streaming JSON writer for reports: objects, arrays, strings, numbers, booleans.
/// Non-finite numbers are written as null (JSON has no NaN), so a report is always valid JSON.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace balloon::jobs {

/// Builds one JSON document in memory. Keys are written in call order; nesting is checked.
class JsonWriter {
 public:
  /// Starts an object; inside an object pass its key, at the top level or in an array pass none.
  JsonWriter& begin_object(std::string_view key = {});
  JsonWriter& end_object();
  /// Starts an array; same key rule as begin_object.
  JsonWriter& begin_array(std::string_view key = {});
  JsonWriter& end_array();

  /// A member of the current object (`key`) or an element of the current array (key empty).
  JsonWriter& value(std::string_view key, std::string_view text);
  JsonWriter& value(std::string_view key, const char* text) { return value(key, std::string_view(text)); }
  JsonWriter& value(std::string_view key, double number);
  JsonWriter& value(std::string_view key, int number) { return value(key, static_cast<long long>(number)); }
  JsonWriter& value(std::string_view key, long long number);
  JsonWriter& value(std::string_view key, bool flag);
  /// A number, or null when there is none (a value that was never computed is null, never 0).
  JsonWriter& value(std::string_view key, const std::optional<double>& number) {
    return number ? value(key, *number) : raw(key, "null");
  }
  /// Inserts already-serialized JSON (trusted, e.g. a stored report) as a member or element.
  JsonWriter& raw(std::string_view key, std::string_view json);

  /// The document; throws std::logic_error while objects or arrays are still open.
  const std::string& str() const;

 private:
  void prefix(std::string_view key);

  std::string m_out;
  std::vector<bool> m_first;     // per open container: nothing written in it yet
  std::vector<bool> m_is_object; // per open container: object (true) or array (false)
};

/// `text` quoted and escaped as a JSON string.
std::string json_quote(std::string_view text);
/// Shortest text that reads back to the same double ("0.1", "1e-08"); "null" if not finite.
std::string json_number(double number);

}  // namespace balloon::jobs
