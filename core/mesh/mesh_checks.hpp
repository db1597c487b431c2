#pragma once
/// Validation of a balloon mesh: one closed, manifold, consistently oriented triangle surface.
#include <string>
#include <vector>

#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// What validate_balloon_mesh found and what it changed.
struct MeshCheckReport {
  bool flipped = false;                   ///< the mesh was oriented inwards and every face was reversed
  int removed_unreferenced_vertices = 0;  ///< vertices used by no face, removed (indices compacted)
  int vertices = 0;                       ///< #V after the clean-up
  int faces = 0;                          ///< #F
  int edges = 0;                          ///< #E (= 3 #F / 2 on a closed mesh)
  int genus = 0;                          ///< from the Euler characteristic V - E + F = 2 - 2 genus
  double volume_mm3 = 0.0;                ///< enclosed volume after any flip, > 0
  double area_mm2 = 0.0;                  ///< surface area
  double bounding_box_diagonal_mm = 0.0;  ///< size of the mesh
  double min_angle_deg = 0.0;             ///< smallest triangle angle (quality)
  std::vector<std::string> notes;         ///< one sentence per change made to the mesh
};

/// Relative area below which a triangle counts as zero-area: area < ZERO_AREA_RELATIVE * diagonal^2,
/// where diagonal is the bounding-box diagonal of the referenced vertices.
inline constexpr double ZERO_AREA_RELATIVE = 1e-12;

/// Most triangles one vertex may have. The self-intersection check (CGAL's box intersection) meets every
/// pair of a vertex's triangles, since all their boxes hold the vertex, so a fan of d triangles costs
/// d^2 pair tests: 0.3 s at 2,000, 1.1 s at 4,000, minutes at 30,000 (a cone's apex; uncancellable).
inline constexpr int MAX_VERTEX_DEGREE = 2000;

/// Checks that `mesh` (positions in mm) is a valid balloon: non-empty, finite coordinates, face indices
/// in range, no repeated vertex in a face, no zero-area triangle, every edge shared by exactly two
/// faces, at most MAX_VERTEX_DEGREE triangles at a vertex, every vertex fan a single cycle, one connected
/// component, consistent orientation, non-zero volume. On failure returns a one-line message naming the
/// problem and where (vertex, edge or face indices of the input mesh), and leaves `mesh` unchanged. On
/// success it cleans `mesh` in place: removes unreferenced vertices and, if the enclosed volume is
/// negative, reverses every face (report.flipped); the report says what was changed.
Result<MeshCheckReport> validate_balloon_mesh(TriMesh& mesh);

}  // namespace balloon
