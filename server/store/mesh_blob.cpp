#include "store/mesh_blob.hpp"

#include <bit>
#include <cstdint>
#include <cstring>

namespace balloon::store {
namespace {

static_assert(std::endian::native == std::endian::little, "mesh blobs are little-endian; add byte swapping");

constexpr std::string_view MAGIC = "BMSH1";

template <class T>
void append(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

template <class T>
T read_at(std::string_view blob, std::size_t offset) {
  T value;
  std::memcpy(&value, blob.data() + offset, sizeof(T));
  return value;
}

}  // namespace

std::string encode_mesh_blob(const TriMesh& mesh) {
  const auto vertices = static_cast<std::uint32_t>(mesh.vertex_count());
  const auto faces = static_cast<std::uint32_t>(mesh.face_count());
  std::string out;
  out.reserve(MAGIC.size() + 8 + vertices * 24ULL + faces * 12ULL);
  out.append(MAGIC);
  append(out, vertices);
  append(out, faces);
  out.append(reinterpret_cast<const char*>(mesh.vertices.data()), vertices * 3ULL * sizeof(double));
  out.append(reinterpret_cast<const char*>(mesh.faces.data()), faces * 3ULL * sizeof(int));
  return out;
}

Result<TriMesh> decode_mesh_blob(std::string_view blob) {
  const std::size_t header = MAGIC.size() + 8;
  if (blob.size() < header || blob.substr(0, MAGIC.size()) != MAGIC) return fail("not a stored mesh blob");
  const auto vertices = read_at<std::uint32_t>(blob, MAGIC.size());
  const auto faces = read_at<std::uint32_t>(blob, MAGIC.size() + 4);
  const std::size_t expected = header + vertices * 24ULL + faces * 12ULL;
  if (blob.size() != expected) return fail("stored mesh blob has the wrong size");
  TriMesh mesh;
  mesh.vertices.resize(vertices, 3);
  mesh.faces.resize(faces, 3);
  std::memcpy(mesh.vertices.data(), blob.data() + header, vertices * 24ULL);
  std::memcpy(mesh.faces.data(), blob.data() + header + vertices * 24ULL, faces * 12ULL);
  return mesh;
}

std::string encode_positions_f32(const Positions& positions) {
  std::string out;
  out.reserve(static_cast<std::size_t>(positions.size()) * sizeof(float));
  for (Eigen::Index i = 0; i < positions.size(); ++i) append(out, static_cast<float>(positions.data()[i]));
  return out;
}

}  // namespace balloon::store
