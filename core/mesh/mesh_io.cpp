#include "mesh/mesh_io.hpp"

#include "mesh/assimp_reader.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/polygon_triangulation.hpp"

#include <Eigen/Geometry>


#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <vector>

#include <unistd.h>

namespace balloon {

namespace {

const char* const READABLE_FORMATS = "obj, stl, ply, off, gltf, glb";
const char* const WRITABLE_FORMATS = "obj, stl, ply";

std::string normalize_format(std::string format) {
  if (!format.empty() && format.front() == '.') format.erase(0, 1);
  std::transform(format.begin(), format.end(), format.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return format;
}

std::string extension_of(const std::string& path) {
  return normalize_format(std::filesystem::path(path).extension().string());
}

// ---------------------------------------------------------------------------------------------
// Small tokenizer shared by the OBJ and OFF parsers.

/// Splits `text` into lines (LF or CRLF), one at a time.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : m_text(text) {}
  bool next(std::string_view& line) {
    if (m_pos >= m_text.size()) return false;
    const std::size_t end = std::min(m_text.find('\n', m_pos), m_text.size());
    line = m_text.substr(m_pos, end - m_pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    m_pos = end + 1;
    ++m_line_number;
    return true;
  }
  int line_number() const { return m_line_number; }

 private:
  std::string_view m_text;
  std::size_t m_pos = 0;
  int m_line_number = 0;
};

/// The C locale's white space, without a call per byte: std::isspace (locale-aware, through the PLT) was
/// half of reading an uploaded OBJ (0.8 of 1.7 ms at 2,562 vertices).
constexpr bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

/// Whitespace-separated tokens of a line, with everything from `comment` on removed, into `tokens`
/// (reused from line to line: a 100k-vertex file has 300k lines).
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens, char comment = '#') {
  if (const std::size_t hash = line.find(comment); hash != std::string_view::npos) {
    line = line.substr(0, hash);
  }
  tokens.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

// from_chars is locale-independent and exact, unlike strtod under a foreign LC_NUMERIC. It also reads
// "nan" and "inf", which no balloon has: those are refused here, as bad coordinates.
bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && end == token.data() + token.size() && std::isfinite(value);
}

bool parse_long(std::string_view token, long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && end == token.data() + token.size();
}

std::string quoted(std::string_view token) {
  // Appended piecewise: GCC 12 gives a false -Wrestrict on "'" + std::string (its bug 105329).
  std::string out(1, '\'');
  out += token.substr(0, 40);
  out += token.size() > 40 ? "...'" : "'";
  return out;
}

TriMesh to_mesh(const std::vector<double>& coordinates, const std::vector<int>& indices) {
  TriMesh mesh;
  mesh.vertices = Eigen::Map<const Positions>(coordinates.data(),
                                              static_cast<Eigen::Index>(coordinates.size() / 3), 3);
  mesh.faces =
      Eigen::Map<const Faces>(indices.data(), static_cast<Eigen::Index>(indices.size() / 3), 3);
  return mesh;
}

/// Appends `face` to `indices` as triangles (append_polygon_triangles); false when they would pass
/// `max_faces` (0: no limit).
bool append_face(const std::vector<int>& face, const std::vector<double>& coordinates, std::vector<int>& indices,
                 std::int64_t max_faces) {
  if (max_faces > 0 && static_cast<std::int64_t>(indices.size() / 3 + face.size() - 2) > max_faces) return false;
  append_polygon_triangles(face, coordinates, indices);
  return true;
}

// ---------------------------------------------------------------------------------------------
// OBJ and OFF are parsed here rather than by assimp: assimp gives every face corner its own vertex
// (so the file's vertex order is lost, and OBJ texture seams stay split), and stores single
// precision. Both formats are a few lines of text; this keeps the file's vertices, order and digits.

Result<TriMesh> parse_obj(std::string_view text, const MeshReadLimits& limits) {
  std::vector<double> coordinates;
  std::vector<int> indices;
  LineReader lines(text);
  std::string_view line;
  int face_index = 0;
  std::vector<std::string_view> tokens;
  std::vector<int> face;
  auto where = [&]() { return "line " + std::to_string(lines.line_number()); };
  while (lines.next(line)) {
    split_tokens(line, tokens);
    if (tokens.empty()) continue;
    if (tokens[0] == "v") {
      if (tokens.size() < 4) return fail(where() + ": a vertex needs 3 coordinates");
      if (const std::string over = over_limit_message(static_cast<std::int64_t>(coordinates.size() / 3) + 1,
                                                      limits.max_vertices, "vertices");
          !over.empty()) {
        return fail(over);
      }
      for (int k = 1; k <= 3; ++k) {
        double value = 0.0;
        if (!parse_double(tokens[static_cast<std::size_t>(k)], value)) {
          return fail(where() + ": bad vertex coordinate " + quoted(tokens[static_cast<std::size_t>(k)]));
        }
        coordinates.push_back(value);
      }
    } else if (tokens[0] == "f") {
      if (const std::string over = over_limit_message(face_index + 1, limits.max_faces, "faces"); !over.empty()) {
        return fail(over);
      }
      const std::size_t corners = tokens.size() - 1;
      if (const std::string problem = polygon_corner_problem(static_cast<long>(corners)); !problem.empty())
        return fail("face " + std::to_string(face_index) + " (" + where() + ") " + problem);
      const long vertex_count = static_cast<long>(coordinates.size() / 3);
      face.clear();
      for (std::size_t k = 1; k <= corners; ++k) {
        // "v", "v/vt", "v//vn" or "v/vt/vn": only the position index matters.
        const std::string_view ref = tokens[k].substr(0, tokens[k].find('/'));
        long index = 0;
        if (!parse_long(ref, index) || index == 0) {
          return fail(where() + ": bad vertex reference " + quoted(tokens[k]) + " in face " +
                      std::to_string(face_index));
        }
        // Negative references count back from the last vertex read so far.
        const long zero_based = index > 0 ? index - 1 : vertex_count + index;
        if (zero_based < 0 || zero_based >= vertex_count) {
          return fail("face " + std::to_string(face_index) + " (" + where() + ") refers to vertex " +
                      std::to_string(index) + " but only " + std::to_string(vertex_count) +
                      " vertices precede it");
        }
        face.push_back(static_cast<int>(zero_based));
      }
      if (!append_face(face, coordinates, indices, limits.max_faces))
        return fail(over_limit_message(static_cast<std::int64_t>(indices.size() / 3 + corners - 2), limits.max_faces, "faces"));
      ++face_index;
    }
    // Everything else (vt, vn, o, g, s, usemtl, mtllib, l, p) describes no surface: ignored.
  }
  if (indices.empty()) return fail("no triangles (no 'f' lines)");
  return to_mesh(coordinates, indices);
}

Result<TriMesh> parse_off(std::string_view text, const MeshReadLimits& limits) {
  LineReader lines(text);
  std::string_view line;
  std::vector<std::string_view> tokens;
  // Next line with content; false at the end of the text.
  auto next_tokens = [&]() {
    while (lines.next(line)) {
      split_tokens(line, tokens);
      if (!tokens.empty()) return true;
    }
    return false;
  };
  auto where = [&]() { return "line " + std::to_string(lines.line_number()); };

  if (!next_tokens()) return fail("empty file");
  // Header: [ST][C][N][4][n]OFF; the optional prefixes only add per-vertex data after x y z.
  const std::string_view header = tokens[0];
  if (header.size() < 3 || header.substr(header.size() - 3) != "OFF") {
    return fail("not an OFF file (first word " + quoted(header) + ", expected OFF)");
  }
  const std::string_view prefix = header.substr(0, header.size() - 3);
  if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
    return fail("unsupported OFF variant " + quoted(header) + " (only 3D OFF, COFF, NOFF, STOFF)");
  }
  std::vector<std::string_view> counts(tokens.begin() + 1, tokens.end());
  if (!counts.empty() && counts[0] == "BINARY") return fail("binary OFF is not supported");
  if (counts.empty()) {
    if (!next_tokens()) return fail("missing vertex and face counts");
    counts = tokens;
  }
  long vertex_count = 0, face_count = 0;
  if (counts.size() < 2 || !parse_long(counts[0], vertex_count) || !parse_long(counts[1], face_count) ||
      vertex_count < 0 || face_count < 0 || vertex_count > INT32_MAX / 3 || face_count > INT32_MAX / 3) {
    return fail(where() + ": bad vertex and face counts");
  }
  // A header bomb declares more than the file can hold: a vertex takes at least 6 bytes ("0 0 0\n"),
  // a face at least 8 ("3 0 1 2\n"). Refused before anything is allocated.
  if (static_cast<std::size_t>(vertex_count) > text.size() / 6 || static_cast<std::size_t>(face_count) > text.size() / 8) {
    return fail(where() + ": the header declares " + std::to_string(vertex_count) + " vertices and " +
                std::to_string(face_count) + " faces, more than a file of " + std::to_string(text.size()) +
                " bytes can hold");
  }
  for (const std::string& over : {over_limit_message(vertex_count, limits.max_vertices, "vertices"),
                                  over_limit_message(face_count, limits.max_faces, "faces")}) {
    if (!over.empty()) return fail(over);
  }

  std::vector<double> coordinates;
  coordinates.reserve(static_cast<std::size_t>(3 * vertex_count));
  for (long v = 0; v < vertex_count; ++v) {
    if (!next_tokens()) {
      return fail("file ends after " + std::to_string(v) + " of " + std::to_string(vertex_count) +
                  " vertices");
    }
    if (tokens.size() < 3) return fail(where() + ": vertex " + std::to_string(v) + " needs 3 coordinates");
    for (std::size_t k = 0; k < 3; ++k) {
      double value = 0.0;
      if (!parse_double(tokens[k], value)) {
        return fail(where() + ": bad coordinate " + quoted(tokens[k]) + " of vertex " + std::to_string(v));
      }
      coordinates.push_back(value);
    }
  }
  std::vector<int> indices;
  indices.reserve(static_cast<std::size_t>(3 * face_count));
  std::vector<int> face;
  for (long f = 0; f < face_count; ++f) {
    if (!next_tokens()) {
      return fail("file ends after " + std::to_string(f) + " of " + std::to_string(face_count) + " faces");
    }
    long corners = 0;
    if (!parse_long(tokens[0], corners)) {
      return fail(where() + ": bad vertex count " + quoted(tokens[0]) + " of face " + std::to_string(f));
    }
    if (const std::string problem = polygon_corner_problem(corners); !problem.empty())
      return fail("face " + std::to_string(f) + " (" + where() + ") " + problem);
    if (tokens.size() < static_cast<std::size_t>(corners) + 1)
      return fail(where() + ": face " + std::to_string(f) + " lists fewer than its " + std::to_string(corners) + " vertices");
    face.clear();
    for (std::size_t k = 1; k <= static_cast<std::size_t>(corners); ++k) {  // anything after the indices is a colour: ignored
      long index = 0;
      if (!parse_long(tokens[k], index)) {
        return fail(where() + ": bad vertex index " + quoted(tokens[k]) + " in face " + std::to_string(f));
      }
      if (index < 0 || index >= vertex_count) {
        return fail("face " + std::to_string(f) + " (" + where() + ") refers to vertex " +
                    std::to_string(index) + ", out of range 0.." + std::to_string(vertex_count - 1));
      }
      face.push_back(static_cast<int>(index));
    }
    if (!append_face(face, coordinates, indices, limits.max_faces))
      return fail(over_limit_message(static_cast<std::int64_t>(indices.size() / 3) + corners - 2, limits.max_faces, "faces"));
  }
  if (indices.empty()) return fail("no triangles (the header declares 0 faces)");
  return to_mesh(coordinates, indices);
}

bool uses_assimp(const std::string& format) {
  return format == "stl" || format == "ply" || format == "gltf" || format == "glb";
}

Result<TriMesh> parse_text_format(const std::string& bytes, const std::string& format, const MeshReadLimits& limits) {
  return format == "obj" ? parse_obj(bytes, limits) : parse_off(bytes, limits);
}

template <class T>
Result<T> with_context(Result<T> result, const std::string& context) {
  if (result.ok()) return result;
  return fail(context + result.error());
}

// ---------------------------------------------------------------------------------------------
// Writers.

void append_u16(std::string& out, std::uint16_t v) {
  out.push_back(static_cast<char>(v & 0xffU));
  out.push_back(static_cast<char>(v >> 8));
}
void append_u32(std::string& out, std::uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<char>((v >> shift) & 0xffU));
}
void append_u64(std::string& out, std::uint64_t v) {
  for (int shift = 0; shift < 64; shift += 8) out.push_back(static_cast<char>((v >> shift) & 0xffU));
}
void append_f32(std::string& out, double v) { append_u32(out, std::bit_cast<std::uint32_t>(static_cast<float>(v))); }
void append_f64(std::string& out, double v) { append_u64(out, std::bit_cast<std::uint64_t>(v)); }

/// %.*g with `digits` significant digits, but locale-independent.
void append_number(std::string& out, double v, int digits) {
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::general, digits);
  out.append(buffer, error == std::errc() ? end : buffer);
}

/// Significant digits that keep a vertex to 1e-8 of the mesh's size: 9 about the origin, more for a mesh
/// standing far from it (at 1e5 mm, 9 digits had kept a 40 mm sphere's vertices to 1e-4 mm; at 1e12 mm its
/// x coordinates all read 1e+12), at most the 17 that round-trip a double.
int significant_digits(const Positions& vertices) {
  constexpr int DIGITS_AT_THE_ORIGIN = 9, ROUND_TRIP_DIGITS = 17;
  if (vertices.rows() == 0 || !vertices.allFinite()) return DIGITS_AT_THE_ORIGIN;
  const double farthest = vertices.cwiseAbs().maxCoeff();
  const double size = bounding_box_diagonal(vertices);
  if (!(size > 0.0) || farthest <= size) return DIGITS_AT_THE_ORIGIN;
  return std::min(ROUND_TRIP_DIGITS, DIGITS_AT_THE_ORIGIN + static_cast<int>(std::ceil(std::log10(farthest / size))));
}

void check_indices(const TriMesh& mesh) {
  if (mesh.face_count() > 0 &&
      (mesh.faces.minCoeff() < 0 || mesh.faces.maxCoeff() >= mesh.vertex_count())) {
    throw std::invalid_argument("write_mesh: a face index is out of range 0.." +
                                std::to_string(mesh.vertex_count() - 1));
  }
}

std::string obj_bytes(const TriMesh& mesh) {
  std::string out = "# balloon mesh, units mm: " + std::to_string(mesh.vertex_count()) + " vertices, " +
                    std::to_string(mesh.face_count()) + " faces\n";
  out.reserve(out.size() + static_cast<std::size_t>(mesh.vertex_count()) * 40 +
              static_cast<std::size_t>(mesh.face_count()) * 24);
  const int digits = significant_digits(mesh.vertices);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    out += "v";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, mesh.vertices(v, k), digits);
    }
    out += '\n';
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      char buffer[16];
      buffer[0] = ' ';
      const auto end = std::to_chars(buffer + 1, buffer + sizeof buffer, mesh.faces(f, k) + 1).ptr;
      out.append(buffer, end);
    }
    out += '\n';
  }
  return out;
}

std::string stl_bytes(const TriMesh& mesh) {
  // The 80-byte header must not start with "solid": readers would take the file for ASCII.
  std::string out = "binary STL written by balloon, units mm";
  out.resize(80, ' ');
  append_u32(out, static_cast<std::uint32_t>(mesh.face_count()));
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Eigen::RowVector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::RowVector3d b = mesh.vertices.row(mesh.faces(f, 1));
    const Eigen::RowVector3d c = mesh.vertices.row(mesh.faces(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).stableNormalized();
    for (const Eigen::RowVector3d& p : {n, a, b, c}) {
      for (int k = 0; k < 3; ++k) append_f32(out, p(k));
    }
    append_u16(out, 0);
  }
  return out;
}

std::string ply_bytes(const TriMesh& mesh) {
  std::string out =
      "ply\nformat binary_little_endian 1.0\ncomment balloon mesh, units mm\nelement vertex " +
      std::to_string(mesh.vertex_count()) +
      "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
      std::to_string(mesh.face_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) append_f64(out, mesh.vertices(v, k));
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    out.push_back(3);
    for (int k = 0; k < 3; ++k) append_u32(out, static_cast<std::uint32_t>(mesh.faces(f, k)));
  }
  return out;
}

std::string temporary_name(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

}  // namespace

bool is_readable_mesh_format(const std::string& format) {
  const std::string f = normalize_format(format);
  return f == "obj" || f == "off" || uses_assimp(f);
}

bool is_writable_mesh_format(const std::string& format) {
  const std::string f = normalize_format(format);
  return f == "obj" || f == "stl" || f == "ply";
}

Result<TriMesh> read_mesh_from_memory(const std::string& bytes, const std::string& format,
                                      const MeshReadLimits& limits) {
  const std::string f = normalize_format(format);
  const std::string context = "cannot read " + (f.empty() ? std::string("mesh") : f + " mesh") + " data: ";
  if (!is_readable_mesh_format(f)) {
    return fail(context + "unsupported format '" + format + "' (supported: " + READABLE_FORMATS + ")");
  }
  if (bytes.empty()) return fail(context + "no data");
  if (!uses_assimp(f)) return with_context(parse_text_format(bytes, f, limits), context);
  return with_context(read_with_assimp(bytes, f, limits), context);
}

Result<TriMesh> read_mesh(const std::string& path) {
  const std::string context = "cannot read mesh '" + path + "': ";
  const std::string f = extension_of(path);
  if (f.empty()) return fail(context + "no file extension (supported: " + READABLE_FORMATS + ")");
  if (!is_readable_mesh_format(f)) {
    return fail(context + "unsupported format '." + f + "' (supported: " + READABLE_FORMATS + ")");
  }
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) return fail(context + "no such file");
  if (std::filesystem::is_directory(status)) return fail(context + "is a directory");

  if (uses_assimp(f)) {
    // Through the file (not memory) so that a .gltf finds its external buffers.
    std::ifstream probe(path, std::ios::binary);
    if (!probe) return fail(context + "cannot open the file (" + std::strerror(errno) + ")");
    return with_context(read_file_with_assimp(path, MeshReadLimits{}), context);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(context + "cannot open the file (" + std::strerror(errno) + ")");
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) return fail(context + "read error");
  if (bytes.empty()) return fail(context + "the file is empty");
  return with_context(parse_text_format(bytes, f, MeshReadLimits{}), context);
}

std::string write_mesh_to_memory(const TriMesh& mesh, const std::string& format) {
  const std::string f = normalize_format(format);
  check_indices(mesh);
  if (f == "obj") return obj_bytes(mesh);
  if (f == "stl") return stl_bytes(mesh);
  if (f == "ply") return ply_bytes(mesh);
  throw std::invalid_argument("write_mesh_to_memory: unsupported format '" + format + "' (supported: " +
                              WRITABLE_FORMATS + ")");
}

Result<bool> write_mesh(const TriMesh& mesh, const std::string& path) {
  const std::string context = "cannot write mesh '" + path + "': ";
  const std::string f = extension_of(path);
  if (!is_writable_mesh_format(f)) {
    return fail(context + (f.empty() ? std::string("no file extension") : "unsupported format '." + f + "'") +
                " (supported: " + WRITABLE_FORMATS + ")");
  }
  const std::string bytes = write_mesh_to_memory(mesh, f);
  const std::string temporary = temporary_name(path);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return fail(context + "cannot create a file there (" + std::strerror(errno) + ")");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return fail(context + "write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return fail(context + ec.message());
  }
  return true;
}

}  // namespace balloon
