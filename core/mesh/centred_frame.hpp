#pragma once
/// Meshes far from the origin: the physics is blind to where a balloon stands, its floating point is not.
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// The translation that puts a mesh's bounding-box centre at the origin. The solvers work there and hand
/// their positions back in the caller's frame, so rounding follows the balloon's size, not its distance
/// from the origin: a 40 mm sphere placed 1 km away (coordinates near 1e6 mm) had an enclosed volume wrong
/// by more than itself (sums of products near 1e18 mm^3) and could not be inflated; at 100 m it took 99
/// Newton steps instead of 2, and its design could not start.
class CentredFrame {
 public:
  explicit CentredFrame(const Positions& vertices);

  /// Caller's positions (mm) -> the centred frame; an empty matrix stays empty.
  Positions centred(const Positions& caller) const;
  /// Centred positions (mm) -> the caller's frame; an empty matrix stays empty.
  Positions caller(const Positions& centred) const;

 private:
  Eigen::RowVector3d m_centre = Eigen::RowVector3d::Zero();
};

}  // namespace balloon
