#pragma once
/// Polygon faces of mesh files (an OBJ from Blender is mostly quads; CAD exports carry n-gon caps) split
/// into the triangles the membrane model is built on.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace balloon {

/// The most corners a polygon face may have (real meshes' caps have tens to a couple of hundred); a
/// hostile face of a million corners is refused before any work.
constexpr int MAX_POLYGON_CORNERS = 256;

/// Why a face of `corners` corners cannot be read (fewer than 3, more than MAX_POLYGON_CORNERS), as the
/// rest of a sentence about the face ("has 2 vertices; a face needs at least 3"), or "".
std::string polygon_corner_problem(long corners);

/// Splits a polygon face into corners - 2 triangles of the face's own winding, as index triples into
/// `corners` (positions in the face's order, at least 3, at most MAX_POLYGON_CORNERS). Ear clipping in
/// the plane of the polygon's Newell normal, so a concave face (an L-shaped cap) splits inside itself and
/// a slightly warped quad splits too. Where no ear is left (a polygon with no area, or one that crosses
/// itself), or after 8 corners^2 point tests (ear clipping's worst case is corners^3: a file of hostile
/// polygons stays linear in its size), the rest is fanned from its first remaining corner.
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Eigen::Vector3d>& corners);

/// Appends the face `face` (vertex indices into `coordinates`, x y z per vertex) to `triangle_indices`
/// (three per triangle): itself when it is a triangle, else its polygon split by triangulate_polygon.
void append_polygon_triangles(const std::vector<int>& face, const std::vector<double>& coordinates,
                              std::vector<int>& triangle_indices);

}  // namespace balloon
