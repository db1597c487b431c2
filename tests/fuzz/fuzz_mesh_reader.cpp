// libFuzzer target for one mesh reader: the bytes go through read_mesh_from_memory exactly as an upload
// does (the server's default limits), then through validate_balloon_mesh when they parse. Built once per
// format, BALLOON_FUZZ_FORMAT naming it ("obj", "off", "stl", "ply", "gltf", "glb").
#include <cstddef>
#include <cstdint>
#include <string>

#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_io.hpp"
#include "mesh/mesh_read_limits.hpp"

#ifndef BALLOON_FUZZ_FORMAT
#error "define BALLOON_FUZZ_FORMAT to the mesh format this target reads"
#endif

namespace {

// balloon-server's --max-mesh-vertices default; the face limit follows from it as on the server.
constexpr std::int64_t SERVER_MAX_VERTICES = 200000;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  balloon::Result<balloon::TriMesh> mesh =
      balloon::read_mesh_from_memory(bytes, BALLOON_FUZZ_FORMAT, balloon::upload_limits(SERVER_MAX_VERTICES));
  if (!mesh) {
    // Every refusal is one bounded line: a message that echoes the input whole is a finding too.
    if (mesh.error().empty() || mesh.error().size() > 2000 || mesh.error().find_first_of("\r\n") != std::string::npos) __builtin_trap();
    return 0;
  }
  if (mesh->vertex_count() > SERVER_MAX_VERTICES || mesh->face_count() > 4 * SERVER_MAX_VERTICES) __builtin_trap();
  balloon::Result<balloon::MeshCheckReport> report = balloon::validate_balloon_mesh(*mesh);
  if (!report && (report.error().empty() || report.error().size() > 2000)) __builtin_trap();
  return 0;
}
