#pragma once
/// STL, PLY, glTF and GLB through assimp: the only place that includes assimp. No assimp type appears here.
#include <string>

#include "mesh/mesh_read_limits.hpp"
#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// Reads `bytes` (a whole file of `format`: "stl", "ply", "gltf" or "glb", lower case) and nothing else:
/// assimp gets an I/O system that serves only these bytes, so a glTF naming another file (an external
/// buffer or image, `/etc/passwd`, `/dev/zero`) is refused with that name and no file is opened. glTF
/// URIs must be `data:` URIs. Counts declared in a header (binary STL, PLY) are checked against `limits`
/// before assimp allocates; the parsed mesh is checked again. Vertices are welded by exact position in
/// linear time after non-finite coordinates are refused. Positions in file units (read as mm).
Result<TriMesh> read_with_assimp(const std::string& bytes, const std::string& format, const MeshReadLimits& limits);

/// As read_with_assimp, from a file the user named on this machine: a .gltf may then refer to buffers
/// beside it (the CLI reads local files this way; the server never does).
Result<TriMesh> read_file_with_assimp(const std::string& path, const MeshReadLimits& limits);

}  // namespace balloon
