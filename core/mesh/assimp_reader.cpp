#include "mesh/assimp_reader.hpp"

#include "mesh/gltf_layout_check.hpp"
#include "mesh/polygon_triangulation.hpp"

#include <Eigen/Geometry>

#include <assimp/BaseImporter.h>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/importerdesc.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace balloon {

namespace {

/// The name under which the uploaded bytes are served to assimp; any other name is refused.
const std::string MEMORY_FILE_NAME = AI_MEMORYIO_MAGIC_FILENAME;

/// Node trees deeper than this are refused rather than walked (a hostile glTF can nest nodes freely).
constexpr int MAX_NODE_DEPTH = 256;

/// Mentions of refused files kept for the message; the count is always given.
constexpr std::size_t NAMED_REFUSALS = 3;

std::string one_line(std::string text) {
  std::replace_if(text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

/// At most 80 characters of `text` in quotes, control and non-ASCII bytes shown as '?': messages stay one
/// printable line whatever the upload holds.
std::string quoted(std::string_view text) {
  std::string out(1, '\'');
  for (const char c : text.substr(0, 80)) {
    out += static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f ? '?' : c;
  }
  out += text.size() > 80 ? "...'" : "'";
  return out;
}

/// An assimp I/O system that can open exactly one file: the uploaded bytes. assimp's own
/// MemoryIOSystem falls back to the real file system for every other name, which let a glTF buffer
/// `uri` make the server read (and probe for) its own files. Every other name is refused and recorded.
class SealedMemoryIOSystem : public Assimp::IOSystem {
 public:
  SealedMemoryIOSystem(const std::string& bytes, std::string name) : m_bytes(bytes), m_name(std::move(name)) {}

  bool Exists(const char* file) const override { return file != nullptr && m_name == file; }
  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* file, const char* /*mode*/) override {
    if (file != nullptr && m_name == file) {
      // MemoryIOStream does not take ownership of the buffer: m_bytes outlives the import.
      return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(m_bytes.data()), m_bytes.size());
    }
    // assimp may ask for one name several times: the message names each once.
    const std::string name = file == nullptr ? "" : file;
    if (std::find(m_refused.begin(), m_refused.end(), name) == m_refused.end()) m_refused.push_back(name);
    return nullptr;
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }
  bool ComparePaths(const char* one, const char* second) const override { return std::strcmp(one, second) == 0; }

  /// Distinct names assimp asked for other than the uploaded file, in order.
  const std::vector<std::string>& refused() const { return m_refused; }

 private:
  const std::string& m_bytes;
  std::string m_name;
  std::vector<std::string> m_refused;
};

// ---------------------------------------------------------------------------------------------
// Checks on the raw bytes, before assimp allocates anything.

std::uint32_t read_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(k)]);
  return v;
}

/// The JSON text of a .gltf, or the JSON chunk of a .glb ("" with `error` set when the container is bad).
std::string_view gltf_json_text(std::string_view bytes, const std::string& format, std::string& error) {
  if (format == "gltf") return bytes;
  // GLB: 12-byte header (magic "glTF", version, length), then chunks of (length, type, data); JSON first.
  if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF") {
    error = "not a GLB file (no 'glTF' header)";
    return {};
  }
  const std::uint32_t json_length = read_u32(bytes, 12);
  if (bytes.substr(16, 4) != "JSON" || json_length > bytes.size() - 20) {
    error = "bad GLB: the first chunk is not a JSON chunk within the file";
    return {};
  }
  return bytes.substr(20, json_length);
}

/// The length of a GLB's binary chunk as assimp finds it (0 if there is none), or empty with `error` set
/// when the chunk runs past the file. Chunks start on 4-byte boundaries; the BIN chunk follows the JSON one.
std::optional<std::uint64_t> glb_bin_length(std::string_view bytes, std::string& error) {
  const std::uint64_t json_end = 20 + ((std::uint64_t{read_u32(bytes, 12)} + 3) / 4) * 4;
  if (std::uint64_t{read_u32(bytes, 8)} < json_end + 8 || bytes.size() < json_end + 8) return 0;
  const std::uint64_t length = read_u32(bytes, static_cast<std::size_t>(json_end));
  if (length > bytes.size() - json_end - 8) {
    error = "bad GLB: the binary chunk (" + std::to_string(length) + " bytes) runs past the end of the file";
    return std::nullopt;
  }
  return length;
}

/// Every `"uri": "..."` value of a glTF JSON text (escapes left as written; a key spelled with escapes
/// is not found here, but the sealed I/O system refuses what it names all the same).
std::vector<std::string_view> gltf_uris(std::string_view json) {
  std::vector<std::string_view> uris;
  const std::string_view key = "\"uri\"";
  for (std::size_t at = json.find(key); at != std::string_view::npos; at = json.find(key, at + key.size())) {
    std::size_t i = at + key.size();
    while (i < json.size() && std::isspace(static_cast<unsigned char>(json[i]))) ++i;
    if (i >= json.size() || json[i] != ':') continue;
    ++i;
    while (i < json.size() && std::isspace(static_cast<unsigned char>(json[i]))) ++i;
    if (i >= json.size() || json[i] != '"') continue;
    const std::size_t start = ++i;
    while (i < json.size() && json[i] != '"') i += json[i] == '\\' ? 2 : 1;
    uris.push_back(json.substr(start, std::min(i, json.size()) - start));
  }
  return uris;
}

/// JSON nesting (objects and arrays) deeper than this is refused: assimp's JSON parser (rapidjson) recurses
/// once per level, and 200,000 levels in a 400 kB upload overflowed the stack and killed the server.
constexpr int MAX_JSON_DEPTH = 64;

/// More JSON objects than this are refused: assimp's glTF importer also recurses once per level of the node
/// tree, which a flat array of 20,000 nodes, each the child of the one before, overflowed (measured under
/// ASan; a balloon upload has a few dozen objects).
constexpr int MAX_JSON_OBJECTS = 4096;

/// "" or why a JSON text nests deeper than MAX_JSON_DEPTH or holds more than MAX_JSON_OBJECTS objects
/// (strings skipped; the syntax is assimp's to check).
std::string check_json_depth(std::string_view json) {
  int depth = 0, objects = 0;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (c == '"') {
      for (++i; i < json.size() && json[i] != '"'; ++i) {
        if (json[i] == '\\') ++i;
      }
    } else if (c == '{' || c == '[') {
      if (c == '{' && ++objects > MAX_JSON_OBJECTS) {
        return "the JSON has more than " + std::to_string(MAX_JSON_OBJECTS) + " objects (at byte " + std::to_string(i) + ")";
      }
      if (++depth > MAX_JSON_DEPTH) {
        return "the JSON is nested deeper than " + std::to_string(MAX_JSON_DEPTH) + " levels (at byte " + std::to_string(i) + ")";
      }
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return {};
}

/// "" or why a glTF/GLB nests too deep, refers to data outside itself or has a layout assimp mishandles.
std::string check_gltf_uris(std::string_view bytes, const std::string& format) {
  std::string error;
  const std::string_view json = gltf_json_text(bytes, format, error);
  if (!error.empty()) return error;
  if (std::string problem = check_json_depth(json); !problem.empty()) return problem;
  std::vector<std::string_view> external;
  for (const std::string_view uri : gltf_uris(json)) {
    if (uri.substr(0, 5) != "data:") {
      external.push_back(uri);
      continue;
    }
    // assimp 5.2 leaks the buffer it decodes when the base64 turns out bad (tests/fuzz/README.md): check first.
    const std::size_t comma = uri.find(',');
    const std::string_view media = uri.substr(0, comma);
    if (comma == std::string_view::npos || media.size() < 7 || media.substr(media.size() - 7) != ";base64") {
      return "a data: URI that is not base64 (" + quoted(uri.substr(0, 40)) + "); only base64 data: URIs are accepted";
    }
    // A media type as MIME spells it (assimp misreads a long odd one and then fails on the base64).
    const std::string_view type = media.substr(5, media.size() - 12);
    if (type.size() > 64 || type.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789/+.-") !=
                                std::string_view::npos) {
      return "a data: URI with a bad media type (" + quoted(type.substr(0, 40)) + ")";
    }
    std::string_view payload = uri.substr(comma + 1);
    if (payload.size() % 4 != 0) return "bad base64 in a data: URI (its length is not a multiple of 4)";
    for (int pad = 0; pad < 2 && !payload.empty() && payload.back() == '='; ++pad) payload.remove_suffix(1);
    const std::size_t bad = payload.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/");
    if (bad != std::string_view::npos) {
      return "bad base64 in a data: URI (character " + std::to_string(comma + 1 + bad) + " of the URI)";
    }
  }
  if (external.empty()) {
    // The layout assimp trusts: accessors within their buffer views, and so on (gltf_layout_check.hpp).
    std::optional<std::uint64_t> bin;
    if (format == "glb" && !(bin = glb_bin_length(bytes, error))) return error;
    return check_gltf_layout(json, bin);
  }
  std::string message = "refers to " + std::to_string(external.size()) + " external file" +
                        (external.size() > 1 ? "s" : "") + " (uri " + quoted(external[0]);
  if (external.size() > 1) message += ", ...";
  return message + "); only embedded data: URIs are accepted (use a .glb or embed the buffers)";
}

bool parse_count(std::string_view token, std::uint64_t& value) {
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && end == token.data() + token.size();
}

/// Words of one line, separated by spaces and tabs; a CR ends the line (CRLF). A CR inside a line is left in
/// a word, so that the word is refused: assimp does not take it for white space.
std::vector<std::string_view> words_of(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

bool is_ply_scalar_type(std::string_view type) {
  for (const std::string_view known : {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8",
                                       "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"}) {
    if (type == known) return true;
  }
  return false;
}

bool is_ply_name(std::string_view name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

/// True if `token` is a number as the ASCII formats write them (digits, sign, point, exponent; no nan or inf).
bool is_number_token(std::string_view token) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    // One sign only: "+-1" passed from_chars after the '+' went, and assimp 5.2 leaked on it (fuzz_mesh_ply).
    if (!token.empty() && token.front() == '-') return false;
  }
  double value = 0.0;
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error != std::errc::invalid_argument && end == token.data() + token.size() &&
         token.find_first_not_of("0123456789+-.eE") == std::string_view::npos;
}

/// One property of a PLY element: a scalar, or a list (a count, then that many values).
struct PlyProperty {
  bool list = false;
  std::string_view count_type;  ///< lists only
  std::string_view value_type;
};
struct PlyElement {
  std::string_view name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

bool is_ply_integer_type(std::string_view type) {
  return type != "float" && type != "double" && type != "float32" && type != "float64";
}

/// True if `token` is a value of PLY `type`: any number for the float types, an integer (unsigned for the
/// u types) otherwise.
bool is_ply_value(std::string_view token, std::string_view type) {
  if (!is_number_token(token)) return false;
  if (!is_ply_integer_type(type)) return true;
  if (token.find_first_of(".eE") != std::string_view::npos) return false;
  return type.front() != 'u' || token.front() != '-';
}

/// "" or why an ASCII PLY body does not hold, line by line, the elements its header declares: each
/// instance one line with one value per scalar property and a count then that many values per list.
/// assimp 5.2 leaks the element arrays when a value does not parse or the lines fall out of step
/// (tests/fuzz/README.md).
std::string check_ascii_ply_body(std::string_view text, const std::vector<PlyElement>& elements, int first_line) {
  std::size_t at = 0;
  int line_number = first_line - 1;
  for (const PlyElement& element : elements) {
    for (std::uint64_t instance = 0; instance < element.count; ++instance) {
      std::vector<std::string_view> words;
      while (words.empty() && at < text.size()) {  // blank lines are skipped
        const std::size_t newline = std::min(text.find('\n', at), text.size());
        words = words_of(text.substr(at, newline - at));
        at = newline + 1;
        ++line_number;
      }
      const std::string where = "bad PLY data: line " + std::to_string(line_number) + ": ";
      if (words.empty()) return "bad PLY data: the file ends before the header's elements do";
      std::size_t k = 0;
      for (const PlyProperty& property : element.properties) {
        std::uint64_t values = 1;
        if (property.list) {
          if (k >= words.size() || !is_ply_value(words[k], property.count_type) || !parse_count(words[k], values)) {
            return where + "expected a list length";
          }
          ++k;
        }
        for (std::uint64_t v = 0; v < values; ++v, ++k) {
          if (k >= words.size()) return where + "fewer values than the header's properties";
          if (!is_ply_value(words[k], property.value_type)) {
            return where + quoted(words[k].substr(0, 40)) + " is not a " + std::string(property.value_type);
          }
        }
      }
      if (k != words.size()) return where + "more values than the header's properties";
    }
  }
  return {};
}

/// Bytes of one value of PLY scalar `type`.
std::uint64_t ply_type_size(std::string_view type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "double" || type == "float64") return 8;
  return 4;  // int, uint, float and their sized names
}

/// "" or why a binary PLY body does not hold the elements its header declares: each list's length (of an
/// integer type, `big_endian` or not) must be non-negative and its values, like every scalar, within the
/// bytes. assimp 5.2 sized a list from a negative length read as unsigned (a 30 kB file asked for 32 GB),
/// and leaked the mesh built so far when a list ran past the end. Every property takes at least one byte,
/// so the walk is linear in the body.
std::string check_binary_ply_body(std::string_view body, const std::vector<PlyElement>& elements, bool big_endian) {
  std::uint64_t at = 0;
  for (const PlyElement& element : elements) {
    if (element.properties.empty()) continue;  // only with count 0 (checked with the header)
    for (std::uint64_t instance = 0; instance < element.count; ++instance) {
      const auto where = [&] { return "bad PLY data: " + std::string(element.name) + " " + std::to_string(instance) + ": "; };
      for (const PlyProperty& property : element.properties) {
        std::uint64_t values = 1;
        if (property.list) {
          const std::uint64_t size = ply_type_size(property.count_type);
          if (size > body.size() - at) return where() + "the data ends before the header's elements do";
          std::uint64_t raw = 0;
          for (std::uint64_t k = 0; k < size; ++k) {
            const auto byte = static_cast<unsigned char>(body[static_cast<std::size_t>(at + (big_endian ? k : size - 1 - k))]);
            raw = (raw << 8) | byte;
          }
          at += size;
          const bool is_signed = property.count_type.front() != 'u';
          if (is_signed && (raw >> (8 * size - 1)) != 0) return where() + "a negative list length";
          values = raw;
        }
        const std::uint64_t bytes = values * ply_type_size(property.value_type);  // values < 2^32: no overflow
        if (bytes > body.size() - at) return where() + "the data ends before the header's elements do";
        at += bytes;
      }
    }
  }
  return {};
}

/// "" or why a PLY header is malformed, or declares counts that the bytes cannot hold or that are over the
/// limits. The grammar is checked line by line here because assimp 5.2's PLY parser loops for ever on
/// some malformed headers (an element without a name, a property line cut short): see tests/fuzz/README.md.
constexpr int MAX_PLY_HEADER_LINES = 1000;

std::string check_ply_header(std::string_view bytes, const MeshReadLimits& limits) {
  std::size_t at = 0;
  int line_number = 0;
  bool have_format = false, have_end = false, ascii = false, big_endian = false;
  std::uint64_t vertex_count = 0, face_count = 0;
  std::vector<PlyElement> elements;
  std::unordered_set<std::string_view> element_names;
  while (at < bytes.size() && !have_end) {
    const std::size_t newline = std::min(bytes.find('\n', at), bytes.size());
    const std::string_view line = bytes.substr(at, newline - at);
    at = newline + 1;
    ++line_number;
    // assimp 5.2 reads the header in time quadratic in its lines (a 100,000-line header of comments took
    // 17 s of memmove); real headers have tens.
    if (line_number > MAX_PLY_HEADER_LINES) {
      return "bad PLY header: more than " + std::to_string(MAX_PLY_HEADER_LINES) + " lines before end_header";
    }
    const std::vector<std::string_view> words = words_of(line);
    const std::string where = "bad PLY header: line " + std::to_string(line_number) + ": ";
    if (line_number == 1) {
      if (words.size() != 1 || words[0] != "ply") return "not a PLY file (the first line is not 'ply')";
      continue;
    }
    if (words.empty()) return where + "empty line";
    if (words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "format") {
      if (have_format || words.size() != 3 ||
          (words[1] != "ascii" && words[1] != "binary_little_endian" && words[1] != "binary_big_endian") ||
          words[2] != "1.0") {
        return where + "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'";
      }
      have_format = true;
      ascii = words[1] == "ascii";
      big_endian = words[1] == "binary_big_endian";
    } else if (words[0] == "element") {
      std::uint64_t count = 0;
      if (words.size() != 3 || !is_ply_name(words[1]) || !parse_count(words[2], count)) {
        return where + "expected 'element NAME COUNT'";
      }
      // assimp 5.2 sizes the vertex array from one 'element vertex' and fills it from another: a header
      // declaring 12 vertices of x only, then 13 of x y z, wrote past the array's end (fuzz_mesh_ply).
      if (!element_names.insert(words[1]).second) {
        return where + "element " + quoted(words[1]) + " is declared twice";
      }
      if (words[1] == "vertex") vertex_count = count;
      if (words[1] == "face") face_count = count;
      if (!elements.empty() && elements.back().count > 0 && elements.back().properties.empty()) {
        return where + "element '" + std::string(elements.back().name) + "' has no properties";
      }
      elements.push_back(PlyElement{words[1], count, {}});
    } else if (words[0] == "property") {
      const bool list = words.size() == 5 && words[1] == "list" && is_ply_scalar_type(words[2]) &&
                        is_ply_scalar_type(words[3]) && is_ply_name(words[4]);
      const bool scalar = words.size() == 3 && is_ply_scalar_type(words[1]) && is_ply_name(words[2]);
      if (!list && !scalar) return where + "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'";
      // assimp 5.2 reads a float length as any number (a huge one leaked the mesh built so far).
      if (list && !is_ply_integer_type(words[2])) {
        return where + "a list's length type must be an integer type, not " + quoted(words[2]);
      }
      if (elements.empty()) return where + "a property before any element";
      elements.back().properties.push_back(list ? PlyProperty{true, words[2], words[3]} : PlyProperty{false, {}, words[1]});
    } else if (words[0] == "end_header" && words.size() == 1) {
      have_end = true;
    } else {
      return where + "unknown keyword " + quoted(words[0].substr(0, 40));
    }
  }
  if (!elements.empty() && elements.back().count > 0 && elements.back().properties.empty()) {
    return "bad PLY header: element '" + std::string(elements.back().name) + "' has no properties";
  }
  if (!have_end) return "bad PLY header: no end_header line";
  if (!have_format) return "bad PLY header: no format line";
  const std::size_t body = bytes.size() - std::min(at, bytes.size());
  for (const auto& [name, count, limit] : {std::tuple{"vertex", vertex_count, limits.max_vertices},
                                          std::tuple{"face", face_count, limits.max_faces}}) {
    // Every element takes at least one byte, so a count beyond the bytes left is a lie.
    if (count > body) {
      return "bad PLY header: it declares " + std::to_string(count) + " " + name + " elements but only " +
             std::to_string(body) + " bytes follow";
    }
    const std::string over = over_limit_message(static_cast<std::int64_t>(count), limit,
                                                std::string_view(name) == "vertex" ? "vertices" : "faces");
    if (!over.empty()) return over;
  }
  if (ascii) return check_ascii_ply_body(bytes.substr(std::min(at, bytes.size())), elements, line_number + 1);
  return check_binary_ply_body(bytes.substr(std::min(at, bytes.size())), elements, big_endian);
}

/// "" or why an STL has more triangles than allowed; binary STL declares its count at byte 80. (Its
/// vertices are known only after welding: SceneMerger checks them.)
std::string check_stl_size(std::string_view bytes, const MeshReadLimits& limits) {
  std::uint64_t faces = 0;
  if (bytes.size() >= 84 && 84 + 50 * static_cast<std::uint64_t>(read_u32(bytes, 80)) == bytes.size()) {
    faces = read_u32(bytes, 80);
  } else {  // ASCII (or a binary file assimp will refuse): count the facets.
    for (std::size_t at = bytes.find("endfacet"); at != std::string_view::npos; at = bytes.find("endfacet", at + 8)) ++faces;
  }
  return over_limit_message(static_cast<std::int64_t>(faces), limits.max_faces, "faces");
}

/// "" or why an ASCII STL is malformed: each facet is "facet normal N N N", "outer loop", three "vertex X Y Z",
/// "endloop", "endfacet", with numbers where numbers go. assimp 5.2 leaks its arrays when a number does not
/// parse or a facet has no vertices (tests/fuzz/README.md).
std::string check_ascii_stl(std::string_view bytes) {
  // What the next line must be: facet (or solid/endsolid), outer loop, vertex x3, endloop, endfacet.
  enum class Next { Facet, OuterLoop, Vertex, EndLoop, EndFacet };
  Next next = Next::Facet;
  int vertices = 0;
  std::size_t at = 0;
  int line_number = 0;
  while (at < bytes.size()) {
    const std::size_t newline = std::min(bytes.find('\n', at), bytes.size());
    const std::vector<std::string_view> words = words_of(bytes.substr(at, newline - at));
    at = newline + 1;
    ++line_number;
    if (words.empty()) continue;
    const std::string where = "bad ASCII STL: line " + std::to_string(line_number) + ": ";
    std::size_t first_number = 0;
    if (next == Next::Facet && (words[0] == "solid" || words[0] == "endsolid")) continue;  // the name is free text
    if (next == Next::Facet && words[0] == "facet" && words.size() >= 2 && words[1] == "normal") {
      first_number = 2;
      next = Next::OuterLoop;
    } else if (next == Next::OuterLoop && words.size() == 2 && words[0] == "outer" && words[1] == "loop") {
      next = Next::Vertex;
      vertices = 0;
      continue;
    } else if (next == Next::Vertex && words[0] == "vertex") {
      first_number = 1;
      if (++vertices == 3) next = Next::EndLoop;
    } else if (next == Next::EndLoop && words.size() == 1 && words[0] == "endloop") {
      next = Next::EndFacet;
      continue;
    } else if (next == Next::EndFacet && words.size() == 1 && words[0] == "endfacet") {
      next = Next::Facet;
      continue;
    } else {
      static constexpr const char* EXPECTED[] = {"'facet normal' or 'endsolid'", "'outer loop'", "'vertex'", "'endloop'",
                                                 "'endfacet'"};
      return where + "expected " + EXPECTED[static_cast<int>(next)] + ", found " + quoted(words[0].substr(0, 40));
    }
    if (words.size() != first_number + 3) {
      return where + "expected 3 numbers after '" + std::string(words[first_number - 1]) + "'";
    }
    for (std::size_t k = first_number; k < words.size(); ++k) {
      if (!is_number_token(words[k])) return where + quoted(words[k].substr(0, 40)) + " is not a number";
    }
  }
  if (next != Next::Facet) return "bad ASCII STL: the last facet is not complete";
  return {};
}

std::string check_before_parse(std::string_view bytes, const std::string& format, const MeshReadLimits& limits) {
  if (format == "gltf" || format == "glb") return check_gltf_uris(bytes, format);
  if (format == "ply") return check_ply_header(bytes, limits);
  if (format == "stl") {
    const bool binary = bytes.size() >= 84 && 84 + 50 * static_cast<std::uint64_t>(read_u32(bytes, 80)) == bytes.size();
    const std::size_t start = std::min(bytes.find_first_not_of(" \t\r\n"), bytes.size());
    if (!binary && bytes.substr(start, 5) == "solid") {
      if (std::string problem = check_ascii_stl(bytes); !problem.empty()) return problem;
    }
    return check_stl_size(bytes, limits);
  }
  return {};
}

// ---------------------------------------------------------------------------------------------
// Scene to mesh.

/// Exact position, -0 folded onto +0 so that the two weld. Only finite positions are keys (NaN never
/// equals itself, so NaN keys that hash alike would make the weld quadratic).
struct PositionKey {
  double x, y, z;
  bool operator==(const PositionKey& other) const = default;
};
struct PositionKeyHash {
  std::size_t operator()(const PositionKey& p) const {
    std::uint64_t h = 1469598103934665603ULL;
    for (const double c : {p.x, p.y, p.z}) {
      h ^= std::bit_cast<std::uint64_t>(c);
      h *= 1099511628211ULL;
      h ^= h >> 29;
    }
    return static_cast<std::size_t>(h);
  }
};

/// Merges every mesh instance of an assimp scene into one welded triangle mesh, within the limits.
class SceneMerger {
 public:
  SceneMerger(const aiScene& scene, const MeshReadLimits& limits) : m_scene(scene), m_limits(limits) {}

  Result<TriMesh> merge() {
    if (m_scene.mRootNode != nullptr) visit(*m_scene.mRootNode, Eigen::Matrix4d::Identity(), 0);
    if (!m_instanced) {
      // No node refers to a mesh (unusual importer output): take the meshes as they are.
      for (unsigned m = 0; m < m_scene.mNumMeshes && m_error.empty(); ++m) {
        append(*m_scene.mMeshes[m], Eigen::Matrix4d::Identity());
      }
    }
    if (!m_error.empty()) return fail(m_error);
    if (m_indices.empty()) {
      return fail(m_skipped_primitives > 0 ? "no triangles (only points or lines)" : "no triangles");
    }
    TriMesh mesh;
    mesh.vertices = Eigen::Map<const Positions>(m_coordinates.data(),
                                                static_cast<Eigen::Index>(m_coordinates.size() / 3), 3);
    mesh.faces = Eigen::Map<const Faces>(m_indices.data(), static_cast<Eigen::Index>(m_indices.size() / 3), 3);
    return mesh;
  }

 private:
  void visit(const aiNode& node, const Eigen::Matrix4d& parent, int depth) {
    if (depth > MAX_NODE_DEPTH) {
      m_error = "the node tree is deeper than " + std::to_string(MAX_NODE_DEPTH) + " levels";
      return;
    }
    Eigen::Matrix4d local;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) local(r, c) = node.mTransformation[r][c];
    }
    const Eigen::Matrix4d transform = parent * local;
    for (unsigned i = 0; i < node.mNumMeshes && m_error.empty(); ++i) {
      if (node.mMeshes[i] < m_scene.mNumMeshes) {
        m_instanced = true;
        append(*m_scene.mMeshes[node.mMeshes[i]], transform);
      }
    }
    for (unsigned i = 0; i < node.mNumChildren && m_error.empty(); ++i) {
      visit(*node.mChildren[i], transform, depth + 1);
    }
  }

  /// Instancing can repeat one mesh many times, so the limits hold for what is merged, not for the file:
  /// faces before a mesh is appended, welded vertices after (an STL stores 3 vertices per triangle).
  void append(const aiMesh& mesh, const Eigen::Matrix4d& transform) {
    m_error = over_limit_message(m_face_index + mesh.mNumFaces, m_limits.max_faces, "faces");
    if (!m_error.empty()) return;
    append_within_face_limit(mesh, transform);
    if (m_error.empty()) {
      m_error = over_limit_message(static_cast<std::int64_t>(m_coordinates.size() / 3), m_limits.max_vertices, "vertices");
    }
  }

  void append_within_face_limit(const aiMesh& mesh, const Eigen::Matrix4d& transform) {
    if (!transform.allFinite()) {
      m_error = "a node transform has a non-finite entry";
      return;
    }
    std::vector<int> welded(mesh.mNumVertices);
    for (unsigned i = 0; i < mesh.mNumVertices; ++i) {
      const aiVector3D& p = mesh.mVertices[i];
      Eigen::Vector3d q = transform.topLeftCorner<3, 3>() * Eigen::Vector3d(p.x, p.y, p.z) +
                          transform.topRightCorner<3, 1>();
      if (!q.allFinite()) {
        m_error = "vertex " + std::to_string(i) + " of mesh " + std::to_string(m_meshes_appended) +
                  " has a non-finite coordinate (NaN or infinite)";
        return;
      }
      for (double& c : q) {
        if (c == 0.0) c = 0.0;  // -0 becomes +0, so that signed zeros weld
      }
      const auto [it, inserted] = m_weld.try_emplace(PositionKey{q.x(), q.y(), q.z()},
                                                     static_cast<int>(m_coordinates.size() / 3));
      if (inserted) m_coordinates.insert(m_coordinates.end(), {q.x(), q.y(), q.z()});
      welded[i] = it->second;
    }
    // glTF rule: a mirroring transform (negative determinant) reverses the winding.
    const bool mirrored = transform.topLeftCorner<3, 3>().determinant() < 0.0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices < 3) {  // a point or a line: no surface
        ++m_skipped_primitives;
        continue;
      }
      if (face.mNumIndices > 3) {
        append_polygon(mesh, face, welded, mirrored);
        if (!m_error.empty()) return;
        ++m_face_index;
        continue;
      }
      for (const int k : mirrored ? std::array{0, 2, 1} : std::array{0, 1, 2}) {
        const unsigned index = face.mIndices[k];
        if (index >= mesh.mNumVertices) {
          m_error = "face " + std::to_string(m_face_index) + " refers to a missing vertex";
          return;
        }
        m_indices.push_back(welded[index]);
      }
      ++m_face_index;
    }
    ++m_meshes_appended;
  }

  /// A polygon face (a PLY's quads) split into triangles, in the mirrored winding when `mirrored`.
  void append_polygon(const aiMesh& mesh, const aiFace& face, const std::vector<int>& welded, bool mirrored) {
    if (const std::string problem = polygon_corner_problem(face.mNumIndices); !problem.empty()) {
      m_error = "face " + std::to_string(m_face_index) + " " + problem;
      return;
    }
    std::vector<int> corners;
    corners.reserve(face.mNumIndices);
    for (unsigned k = 0; k < face.mNumIndices; ++k) {
      if (face.mIndices[k] >= mesh.mNumVertices) {
        m_error = "face " + std::to_string(m_face_index) + " refers to a missing vertex";
        return;
      }
      corners.push_back(welded[face.mIndices[k]]);
    }
    if (mirrored) std::reverse(corners.begin(), corners.end());
    const std::int64_t triangles = static_cast<std::int64_t>(m_indices.size() / 3 + corners.size() - 2);
    m_error = over_limit_message(triangles, m_limits.max_faces, "faces");
    if (m_error.empty()) append_polygon_triangles(corners, m_coordinates, m_indices);
  }

  const aiScene& m_scene;
  const MeshReadLimits& m_limits;
  std::vector<double> m_coordinates;
  std::vector<int> m_indices;
  std::unordered_map<PositionKey, int, PositionKeyHash> m_weld;
  std::int64_t m_face_index = 0;
  int m_meshes_appended = 0;
  int m_skipped_primitives = 0;
  bool m_instanced = false;
  std::string m_error;
};

// No post-processing: aiProcess_Triangulate would hide polygons we must reject, and
// aiProcess_JoinIdenticalVertices welds within an absolute 1e-5 tolerance in file units (merging
// distinct vertices of small meshes) and not across meshes; SceneMerger welds exact positions instead.
constexpr unsigned ASSIMP_FLAGS = 0;

Result<TriMesh> scene_to_mesh(const aiScene* scene, const std::string& error, const MeshReadLimits& limits) {
  if (scene == nullptr) {
    std::string reason = one_line(error);
    // Reading from memory, assimp names the data after a made-up file; say "the data" instead.
    for (std::size_t at = reason.find(MEMORY_FILE_NAME); at != std::string::npos; at = reason.find(MEMORY_FILE_NAME)) {
      std::size_t end = at + MEMORY_FILE_NAME.size();
      while (end < reason.size() && (std::isalnum(static_cast<unsigned char>(reason[end])) || reason[end] == '.')) ++end;
      if (end > at + MEMORY_FILE_NAME.size() && reason[end - 1] == '.') --end;  // keep a sentence's full stop
      reason.replace(at, end - at, "the data");
    }
    // assimp quotes the offending bytes, however many and whatever they are: keep a short printable line.
    for (char& c : reason) {
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    }
    if (reason.size() > 200) reason = reason.substr(0, 200) + "...";
    return fail("parse error: " + (reason.empty() ? std::string("unknown assimp error") : reason));
  }
  return SceneMerger(*scene, limits).merge();
}

/// The importer assimp registers for `format` (an extension); for glTF the 2.0 one, as the upload promises.
Assimp::BaseImporter* importer_for(const Assimp::Importer& importer, const std::string& format) {
  for (std::size_t i = 0; i < importer.GetImporterCount(); ++i) {
    const aiImporterDesc* info = importer.GetImporterInfo(i);
    if (info == nullptr || info->mFileExtensions == nullptr) continue;
    std::istringstream extensions(info->mFileExtensions);
    for (std::string extension; extensions >> extension;) {
      const bool gltf = format == "gltf" || format == "glb";
      if (extension == format && (!gltf || std::string_view(info->mName).find("glTF2") != std::string_view::npos)) {
        return importer.GetImporter(i);
      }
    }
  }
  return nullptr;
}

std::string refused_files_message(const std::vector<std::string>& refused) {
  std::string message = "refers to a file outside the upload (" + quoted(refused.front());
  for (std::size_t i = 1; i < std::min(refused.size(), NAMED_REFUSALS); ++i) message += ", " + quoted(refused[i]);
  if (refused.size() > NAMED_REFUSALS) message += " and " + std::to_string(refused.size() - NAMED_REFUSALS) + " more";
  return message + "); only the uploaded bytes are read";
}

}  // namespace

Result<TriMesh> read_with_assimp(const std::string& bytes, const std::string& format, const MeshReadLimits& limits) {
  if (const std::string problem = check_before_parse(bytes, format, limits); !problem.empty()) return fail(problem);
  const std::string name = MEMORY_FILE_NAME + "." + format;
  Assimp::Importer importer;
  auto* io = new SealedMemoryIOSystem(bytes, name);
  importer.SetIOHandler(io);  // the importer owns and deletes it
  // The declared format's importer only: Importer::ReadFile falls back to guessing the format from the bytes,
  // which hands an upload to any of assimp's ~40 importers (fuzzing reached a heap overflow that way).
  Assimp::BaseImporter* reader = importer_for(importer, format);
  if (reader == nullptr) return fail("this assimp has no " + format + " importer");
  const std::unique_ptr<aiScene> scene(reader->ReadFile(&importer, name, io));
  // Refused names come first: even when assimp carried on without them, the upload was not self-contained.
  if (!io->refused().empty()) return fail(refused_files_message(io->refused()));
  return scene_to_mesh(scene.get(), reader->GetErrorText(), limits);
}

Result<TriMesh> read_file_with_assimp(const std::string& path, const MeshReadLimits& limits) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, ASSIMP_FLAGS);
  return scene_to_mesh(scene, importer.GetErrorString(), limits);
}

}  // namespace balloon
