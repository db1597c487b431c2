#pragma once
/// Compact binary encodings of meshes for the store: exact (float64) meshes for results, float32
/// positions for progress checkpoints. Little-endian, versioned by a magic tag.
#include <string>
#include <string_view>

#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon::store {

/// "BMSH1" + #V, #F (uint32) + #V x 3 float64 positions (mm) + #F x 3 int32 indices.
std::string encode_mesh_blob(const TriMesh& mesh);
/// Reads encode_mesh_blob's output; fails on a truncated or foreign blob.
Result<TriMesh> decode_mesh_blob(std::string_view blob);

/// #V x 3 float32 positions (mm), x0 y0 z0 x1 ..., no header: the progress-stream representation.
std::string encode_positions_f32(const Positions& positions);

}  // namespace balloon::store
