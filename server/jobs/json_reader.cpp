#include "jobs/json_reader.hpp"

#include <cctype>
#include <cstdlib>
#include <string_view>

namespace balloon::jobs {
namespace {

class JsonParser {
 public:
  explicit JsonParser(const std::string& text) : m_text(text) {}

  Result<JsonValue> parse_document() {
    JsonValue value;
    if (!parse_value(value, 0)) return fail("not valid JSON (at byte " + std::to_string(m_at) + ")");
    skip_space();
    if (m_at != m_text.size()) return fail("trailing bytes after the JSON value (at byte " + std::to_string(m_at) + ")");
    return value;
  }

 private:
  static constexpr int MAX_DEPTH = 64;

  void skip_space() {
    while (m_at < m_text.size() && std::isspace(static_cast<unsigned char>(m_text[m_at]))) ++m_at;
  }
  bool literal(std::string_view word) {
    if (m_text.compare(m_at, word.size(), word) != 0) return false;
    m_at += word.size();
    return true;
  }
  bool hex4(unsigned& code) {
    if (m_at + 4 > m_text.size()) return false;
    code = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = m_text[m_at++];
      code <<= 4;
      if (c >= '0' && c <= '9') code |= static_cast<unsigned>(c - '0');
      else if (c >= 'a' && c <= 'f') code |= static_cast<unsigned>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') code |= static_cast<unsigned>(c - 'A' + 10);
      else return false;
    }
    return true;
  }
  static void append_utf8(std::string& out, unsigned code) {
    if (code < 0x80) {
      out += static_cast<char>(code);
    } else if (code < 0x800) {
      out += static_cast<char>(0xC0 | (code >> 6));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      out += static_cast<char>(0xE0 | (code >> 12));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (code >> 18));
      out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (code & 0x3F));
    }
  }
  bool parse_string(std::string& out) {
    if (m_at >= m_text.size() || m_text[m_at] != '"') return false;
    ++m_at;
    while (m_at < m_text.size() && m_text[m_at] != '"') {
      const char c = m_text[m_at++];
      if (static_cast<unsigned char>(c) < 0x20) return false;  // control characters must be escaped
      if (c != '\\') {
        out += c;
        continue;
      }
      if (m_at >= m_text.size()) return false;
      switch (m_text[m_at++]) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'n': out += '\n'; break;
        case 't': out += '\t'; break;
        case 'r': out += '\r'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'u': {
          unsigned code = 0;
          if (!hex4(code)) return false;
          // A surrogate pair encodes one code point above U+FFFF.
          if (code >= 0xD800 && code < 0xDC00 && m_text.compare(m_at, 2, "\\u") == 0) {
            m_at += 2;
            unsigned low = 0;
            if (!hex4(low) || low < 0xDC00 || low >= 0xE000) return false;
            code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
          }
          append_utf8(out, code);
          break;
        }
        default: return false;
      }
    }
    if (m_at >= m_text.size()) return false;
    ++m_at;
    return true;
  }
  bool parse_number(JsonValue& value) {
    // strtod accepts more than JSON (hex, inf, leading '+'): check the JSON grammar's first character.
    const char first = m_text[m_at];
    if (first != '-' && !std::isdigit(static_cast<unsigned char>(first))) return false;
    const char* begin = m_text.c_str() + m_at;
    char* end = nullptr;
    value.number = std::strtod(begin, &end);
    if (end == begin) return false;
    value.kind = JsonValue::Kind::Number;
    m_at += static_cast<size_t>(end - begin);
    return true;
  }
  bool parse_value(JsonValue& value, int depth) {
    if (depth > MAX_DEPTH) return false;
    skip_space();
    if (m_at >= m_text.size()) return false;
    const char c = m_text[m_at];
    if (c == '"') {
      value.kind = JsonValue::Kind::String;
      return parse_string(value.text);
    }
    if (c == '{') {
      value.kind = JsonValue::Kind::Object;
      ++m_at;
      skip_space();
      if (m_at < m_text.size() && m_text[m_at] == '}') return ++m_at, true;
      while (true) {
        skip_space();
        std::string key;
        if (!parse_string(key)) return false;
        skip_space();
        if (m_at >= m_text.size() || m_text[m_at++] != ':') return false;
        JsonValue member;
        if (!parse_value(member, depth + 1)) return false;
        value.members.emplace_back(std::move(key), std::move(member));
        skip_space();
        if (m_at >= m_text.size()) return false;
        if (m_text[m_at] == ',') { ++m_at; continue; }
        if (m_text[m_at] == '}') return ++m_at, true;
        return false;
      }
    }
    if (c == '[') {
      value.kind = JsonValue::Kind::Array;
      ++m_at;
      skip_space();
      if (m_at < m_text.size() && m_text[m_at] == ']') return ++m_at, true;
      while (true) {
        JsonValue item;
        if (!parse_value(item, depth + 1)) return false;
        value.items.push_back(std::move(item));
        skip_space();
        if (m_at >= m_text.size()) return false;
        if (m_text[m_at] == ',') { ++m_at; continue; }
        if (m_text[m_at] == ']') return ++m_at, true;
        return false;
      }
    }
    if (literal("null")) return value.kind = JsonValue::Kind::Null, true;
    if (literal("true")) return value.kind = JsonValue::Kind::Bool, value.boolean = true, true;
    if (literal("false")) return value.kind = JsonValue::Kind::Bool, value.boolean = false, true;
    return parse_number(value);
  }

  const std::string& m_text;
  size_t m_at = 0;
};

}  // namespace

const JsonValue* JsonValue::find(const std::string& key) const {
  for (const auto& [name, value] : members)
    if (name == key) return &value;
  return nullptr;
}

Result<JsonValue> parse_json(const std::string& text) { return JsonParser(text).parse_document(); }

}  // namespace balloon::jobs
