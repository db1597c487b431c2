// Writes the seed corpora of the fuzz targets from tests/data, so that the repository holds no copies:
// every small mesh there (and two icospheres) in each encoding a reader takes (OBJ, OFF, ASCII and binary
// STL and PLY, glTF with an embedded buffer, GLB), and the measurement CSVs as they are.
// Usage: make_fuzz_seeds TESTS_DATA_DIR OUT_DIR  (writes OUT_DIR/<target>/<name>)
#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"

namespace {

namespace fs = std::filesystem;
using balloon::TriMesh;

// Larger seeds slow every mutation; the readers' interesting paths are all reached by small files.
constexpr std::uintmax_t MAX_SEED_SOURCE_BYTES = 40 * 1024;
constexpr std::size_t MAX_SEED_BYTES = 64 * 1024;  // an encoding larger than this (ASCII STL) is left out

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

std::string off_text(const TriMesh& mesh) {
  std::string out = "OFF\n" + std::to_string(mesh.vertex_count()) + " " + std::to_string(mesh.face_count()) + " 0\n";
  for (int v = 0; v < mesh.vertex_count(); ++v)
    out += number(mesh.vertices(v, 0)) + " " + number(mesh.vertices(v, 1)) + " " + number(mesh.vertices(v, 2)) + "\n";
  for (int f = 0; f < mesh.face_count(); ++f)
    out += "3 " + std::to_string(mesh.faces(f, 0)) + " " + std::to_string(mesh.faces(f, 1)) + " " +
           std::to_string(mesh.faces(f, 2)) + "\n";
  return out;
}

std::string ascii_stl(const TriMesh& mesh) {
  std::string out = "solid seed\n";
  for (int f = 0; f < mesh.face_count(); ++f) {
    out += "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.faces(f, k);
      out += "vertex " + number(mesh.vertices(v, 0)) + " " + number(mesh.vertices(v, 1)) + " " +
             number(mesh.vertices(v, 2)) + "\n";
    }
    out += "endloop\nendfacet\n";
  }
  return out + "endsolid seed\n";
}

std::string ascii_ply(const TriMesh& mesh) {
  std::string out = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(mesh.vertex_count()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                    std::to_string(mesh.face_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int v = 0; v < mesh.vertex_count(); ++v)
    out += number(mesh.vertices(v, 0)) + " " + number(mesh.vertices(v, 1)) + " " + number(mesh.vertices(v, 2)) + "\n";
  for (int f = 0; f < mesh.face_count(); ++f)
    out += "3 " + std::to_string(mesh.faces(f, 0)) + " " + std::to_string(mesh.faces(f, 1)) + " " +
           std::to_string(mesh.faces(f, 2)) + "\n";
  return out;
}

void append_u32(std::string& out, std::uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<char>((v >> shift) & 0xffU));
}

/// float32 positions then uint32 indices, as one glTF buffer.
std::string gltf_buffer(const TriMesh& mesh) {
  std::string out;
  for (int v = 0; v < mesh.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) append_u32(out, std::bit_cast<std::uint32_t>(static_cast<float>(mesh.vertices(v, k))));
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k) append_u32(out, static_cast<std::uint32_t>(mesh.faces(f, k)));
  return out;
}

std::string base64(const std::string& bytes) {
  static const char* const ALPHABET = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t n = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 2]);
    out += ALPHABET[(n >> 18) & 63];
    out += ALPHABET[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? ALPHABET[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? ALPHABET[n & 63] : '=';
  }
  return out;
}

/// A glTF 2.0 JSON document with one mesh; `uri` empty for a GLB's own binary chunk.
std::string gltf_json(const TriMesh& mesh, const std::string& uri) {
  const Eigen::RowVector3d lo = mesh.vertices.colwise().minCoeff(), hi = mesh.vertices.colwise().maxCoeff();
  const std::size_t positions_bytes = 12 * static_cast<std::size_t>(mesh.vertex_count());
  const std::size_t indices_bytes = 12 * static_cast<std::size_t>(mesh.face_count());
  std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)";
  json += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":4}]}],)";
  json += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(mesh.vertex_count()) +
          R"(,"type":"VEC3","min":[)" + number(lo(0)) + "," + number(lo(1)) + "," + number(lo(2)) + R"(],"max":[)" +
          number(hi(0)) + "," + number(hi(1)) + "," + number(hi(2)) + "]},";
  json += R"({"bufferView":1,"componentType":5125,"count":)" + std::to_string(3 * mesh.face_count()) +
          R"(,"type":"SCALAR"}],)";
  json += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(positions_bytes) +
          R"(},{"buffer":0,"byteOffset":)" + std::to_string(positions_bytes) + R"(,"byteLength":)" +
          std::to_string(indices_bytes) + "}],";
  json += R"("buffers":[{"byteLength":)" + std::to_string(positions_bytes + indices_bytes) +
          (uri.empty() ? std::string() : R"(,"uri":")" + uri + "\"") + "}]}";
  return json;
}

std::string glb(const TriMesh& mesh) {
  std::string json = gltf_json(mesh, "");
  while (json.size() % 4 != 0) json += ' ';
  std::string bin = gltf_buffer(mesh);
  while (bin.size() % 4 != 0) bin.push_back('\0');
  std::string out = "glTF";
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  append_u32(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON" + json;
  append_u32(out, static_cast<std::uint32_t>(bin.size()));
  out += std::string("BIN\0", 4) + bin;
  return out;
}

void write(const fs::path& dir, const std::string& name, const std::string& bytes) {
  if (bytes.size() > MAX_SEED_BYTES) return;
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

void write_all_encodings(const fs::path& out, const std::string& stem, const TriMesh& mesh) {
  write(out / "fuzz_mesh_obj", stem + ".obj", balloon::write_mesh_to_memory(mesh, "obj"));
  write(out / "fuzz_mesh_off", stem + ".off", off_text(mesh));
  write(out / "fuzz_mesh_stl", stem + "_binary.stl", balloon::write_mesh_to_memory(mesh, "stl"));
  write(out / "fuzz_mesh_stl", stem + "_ascii.stl", ascii_stl(mesh));
  write(out / "fuzz_mesh_ply", stem + "_binary.ply", balloon::write_mesh_to_memory(mesh, "ply"));
  write(out / "fuzz_mesh_ply", stem + "_ascii.ply", ascii_ply(mesh));
  write(out / "fuzz_mesh_gltf", stem + ".gltf",
        gltf_json(mesh, "data:application/octet-stream;base64," + base64(gltf_buffer(mesh))));
  // A refused external buffer too, so that the refusal path is in the corpus from the start.
  write(out / "fuzz_mesh_gltf", stem + "_external.gltf", gltf_json(mesh, "buffer.bin"));
  write(out / "fuzz_mesh_glb", stem + ".glb", glb(mesh));
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_fuzz_seeds TESTS_DATA_DIR OUT_DIR\n");
    return 2;
  }
  const fs::path data = argv[1], out = argv[2];
  write_all_encodings(out, "icosphere0", balloon::make_icosphere(10.0, 0));
  write_all_encodings(out, "icosphere1", balloon::make_icosphere(10.0, 1));
  int meshes = 2, tables = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(data / "meshes")) {
    if (!entry.is_regular_file() || entry.file_size() > MAX_SEED_SOURCE_BYTES) continue;
    const balloon::Result<TriMesh> mesh = balloon::read_mesh(entry.path().string());
    if (!mesh) continue;  // PROVENANCE.md and the like
    const std::string format = entry.path().extension().string().substr(1);
    write(out / ("fuzz_mesh_" + format), entry.path().filename().string(), read_file(entry.path()));
    write_all_encodings(out, entry.path().stem().string(), *mesh);
    ++meshes;
  }
  for (const fs::directory_entry& entry : fs::directory_iterator(data / "materials")) {
    if (entry.path().extension() != ".csv") continue;
    write(out / "fuzz_measurements_csv", entry.path().filename().string(), read_file(entry.path()));
    ++tables;
  }
  std::printf("make_fuzz_seeds: %d meshes x 9 encodings and %d tables in %s\n", meshes, tables, out.c_str());
  return meshes > 2 && tables > 0 ? 0 : 1;
}
