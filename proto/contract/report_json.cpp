#include "contract/report_json.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>
#include <vector>

namespace balloon::contract {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

void append_quoted(std::string& out, const std::string& text) {
  out += '"';
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
          char escaped[8];
          std::snprintf(escaped, sizeof(escaped), "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

/// Shortest text that reads back to the same double; null when not finite (JSON has no NaN).
void append_double(std::string& out, double value) {
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
  out.append(buffer, end);
}

const char* const BASE64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void append_base64(std::string& out, const std::string& bytes) {
  out += '"';
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int shift = 18; shift >= 0; shift -= 6) out += BASE64[(v >> shift) & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += BASE64[(v >> 18) & 63];
    out += BASE64[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? BASE64[(v >> 6) & 63] : '=';
    out += '=';
  }
  out += '"';
}

void append_message(std::string& out, const Message& message);

/// One value of `field` (element `index` of a repeated field, or the singular value for index < 0).
void append_value(std::string& out, const Message& message, const FieldDescriptor* field, int index) {
  const Reflection* reflection = message.GetReflection();
  const bool repeated = index >= 0;
  switch (field->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      out += std::to_string(repeated ? reflection->GetRepeatedInt32(message, field, index)
                                     : reflection->GetInt32(message, field));
      break;
    case FieldDescriptor::CPPTYPE_UINT32:
      out += std::to_string(repeated ? reflection->GetRepeatedUInt32(message, field, index)
                                     : reflection->GetUInt32(message, field));
      break;
    case FieldDescriptor::CPPTYPE_INT64:  // the mapping quotes 64-bit integers
      out += '"' + std::to_string(repeated ? reflection->GetRepeatedInt64(message, field, index)
                                           : reflection->GetInt64(message, field)) + '"';
      break;
    case FieldDescriptor::CPPTYPE_UINT64:
      out += '"' + std::to_string(repeated ? reflection->GetRepeatedUInt64(message, field, index)
                                           : reflection->GetUInt64(message, field)) + '"';
      break;
    case FieldDescriptor::CPPTYPE_DOUBLE:
      append_double(out, repeated ? reflection->GetRepeatedDouble(message, field, index)
                                  : reflection->GetDouble(message, field));
      break;
    case FieldDescriptor::CPPTYPE_FLOAT:
      append_double(out, repeated ? reflection->GetRepeatedFloat(message, field, index)
                                  : reflection->GetFloat(message, field));
      break;
    case FieldDescriptor::CPPTYPE_BOOL:
      out += (repeated ? reflection->GetRepeatedBool(message, field, index) : reflection->GetBool(message, field))
                 ? "true"
                 : "false";
      break;
    case FieldDescriptor::CPPTYPE_ENUM: {
      const auto* value = repeated ? reflection->GetRepeatedEnum(message, field, index)
                                   : reflection->GetEnum(message, field);
      append_quoted(out, value->name());
      break;
    }
    case FieldDescriptor::CPPTYPE_STRING: {
      const std::string text = repeated ? reflection->GetRepeatedString(message, field, index)
                                        : reflection->GetString(message, field);
      if (field->type() == FieldDescriptor::TYPE_BYTES)
        append_base64(out, text);
      else
        append_quoted(out, text);
      break;
    }
    case FieldDescriptor::CPPTYPE_MESSAGE:
      append_message(out, repeated ? reflection->GetRepeatedMessage(message, field, index)
                                   : reflection->GetMessage(message, field));
      break;
  }
}

/// A map field as an object, keys sorted (a map's own order is not stable across processes).
void append_map(std::string& out, const Message& message, const FieldDescriptor* field) {
  const Reflection* reflection = message.GetReflection();
  const FieldDescriptor* key_field = field->message_type()->map_key();
  const FieldDescriptor* value_field = field->message_type()->map_value();
  std::vector<std::pair<std::string, const Message*>> entries;
  for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
    const Message& entry = reflection->GetRepeatedMessage(message, field, i);
    std::string key;
    append_value(key, entry, key_field, -1);
    if (key.empty() || key.front() != '"') key = '"' + key + '"';  // the mapping quotes every key
    entries.emplace_back(std::move(key), &entry);
  }
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out += '{';
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (i > 0) out += ',';
    out += entries[i].first + ':';
    append_value(out, *entries[i].second, value_field, -1);
  }
  out += '}';
}

void append_message(std::string& out, const Message& message) {
  const auto* descriptor = message.GetDescriptor();
  const Reflection* reflection = message.GetReflection();
  out += '{';
  bool first = true;
  for (int f = 0; f < descriptor->field_count(); ++f) {
    const FieldDescriptor* field = descriptor->field(f);
    const bool proto3_optional = field->has_optional_keyword();
    std::string value;
    if (field->is_map()) {
      append_map(value, message, field);
    } else if (field->is_repeated()) {
      value += '[';
      for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
        if (i > 0) value += ',';
        append_value(value, message, field, i);
      }
      value += ']';
    } else if (field->has_presence() && !reflection->HasField(message, field)) {
      // A number never computed is null; anything else that does not apply is left out.
      const bool floating = field->cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE ||
                            field->cpp_type() == FieldDescriptor::CPPTYPE_FLOAT;
      if (!(proto3_optional && floating)) continue;
      value = "null";
    } else {
      append_value(value, message, field, -1);
    }
    if (!first) out += ',';
    first = false;
    append_quoted(out, field->name());
    out += ':';
    out += value;
  }
  out += '}';
}

}  // namespace

std::string report_json(const Message& report) {
  std::string out;
  append_message(out, report);
  out += '\n';
  return out;
}

}  // namespace balloon::contract
