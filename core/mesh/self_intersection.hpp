#pragma once
/// Whether a triangle mesh intersects itself (a printable mold and a sane target must not).
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// True if two non-adjacent triangles of `mesh` (mm) intersect, or two adjacent ones overlap beyond
/// their shared edge or vertex (CGAL's Polygon_mesh_processing::does_self_intersect, exact predicates).
/// `mesh` must be a valid closed or open manifold (see validate_balloon_mesh); throws
/// std::invalid_argument if CGAL rejects a face. Cost: O(#F log #F), ~10 ms for 10k faces.
bool mesh_self_intersects(const TriMesh& mesh);

}  // namespace balloon
