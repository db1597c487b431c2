#pragma once
/// Cap slivers retriangulated for simulation: a triangle whose one vertex lies almost on its opposite
/// edge (angles near 0, 0 and 180 degrees) is replaced, with the neighbour across that edge, by the
/// other diagonal of the pair, without moving any vertex.
#include <array>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// A cap's height across its long edge is a tiny fraction of that edge, so a constant-strain element on
/// it turns any out-of-plane move of its middle vertex into an enormous stretch: the membrane's stiffness
/// there grows like 1 / angle and Hart-Smith's exponential overflows. Below this smallest angle
/// (degrees, a stiffness ~600 times its neighbours') a cap is flipped away. The corpus's mild caps
/// (femur, 0.45-0.9 degrees) inflate as they are, and flipping them too was measured slower (femur at
/// 20 mm: latex x27 and Neo-Hookean x8 took about 300 Newton steps instead of about 110).
constexpr double CAP_SLIVER_ANGLE_DEG = 0.1;

/// The faces of a mesh with its cap slivers flipped away, and which faces changed.
struct CapSliverFlips {
  Faces faces;  ///< #F by 3, the same count and orientation as the input; flipped pairs in place
  std::vector<std::array<int, 2>> flipped_pairs;  ///< the face indices rewritten by each flip, in order
};

/// Flips the edge opposite the obtuse corner of every triangle of `mesh` (closed, manifold, oriented)
/// whose smallest angle is below `sliver_angle_deg`, when the pair's other diagonal is not an edge
/// already, both new triangles face the way the neighbour did, and the worse of their smallest angles
/// beats the pair's. The enclosed volume changes by at most the cap's height (over its long edge) times
/// the neighbour's area / 3.
/// Repeats until no such flip is left. Vertices are untouched, so a field per vertex computed on the
/// flipped faces belongs to the input mesh too.
CapSliverFlips flip_cap_slivers(const TriMesh& mesh, double sliver_angle_deg = CAP_SLIVER_ANGLE_DEG);

}  // namespace balloon
