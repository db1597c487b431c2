#pragma once
/// Carrying a per-vertex field from one triangle surface to points on or near another surface of the
/// same shape (e.g. the same target remeshed at another resolution).
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// The per-vertex `field` of `surface` (#V by 3) evaluated at each of `points` (#P by 3, mm): linear
/// (barycentric) interpolation within the surface triangle closest to the point. Throws
/// std::invalid_argument when the field does not have one row per surface vertex.
Positions transfer_vertex_field(const TriMesh& surface, const Positions& field, const Positions& points);

}  // namespace balloon
