#pragma once
/// The rigid placement P(x) of a shape on fixed reference points by orthogonal Procrustes (the placement
/// the reported error is measured in, surface_distance's rigid_align_to), with its exact linearization.
/// A term f(P(x)) is then rigid-invariant in x, and its gradient is pull_back(grad f at P(x)). The
/// design's E_surf is such a term: evaluated at x's pinned placement instead, the design spent its steps
/// on rigid motion that the next re-placement undid (latex blobby: each re-placement raised the objective
/// by 2-9%, about what the step had gained).
///
/// With y_i = x_i - mean(x), s_i = q_i - mean(q) and M = sum_i s_i y_i^T = R S (polar decomposition),
/// P_i = R y_i + mean(q), and a change dy rotates R by omega = (tr(S) I - S)^-1 sum_i dy_i x R^T s_i.
#include <Eigen/Core>

#include "design/surface_distance.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon {

class ProcrustesPlacement {
 public:
  /// `points` and `reference_points`: #P by 3 (mm), P >= 3, in correspondence.
  ProcrustesPlacement(const Positions& points, const Positions& reference_points);

  /// P(x): the points rigidly placed on the reference (mm).
  const Positions& placed() const { return m_placed; }
  const RigidTransform& transform() const { return m_transform; }
  /// dP = J v for a change v of the points (3#P).
  Eigen::VectorXd push_forward(const Eigen::VectorXd& v) const;
  /// J^T g: the gradient with respect to the points of a function of P whose gradient at P is g (3#P).
  Eigen::VectorXd pull_back(const Eigen::VectorXd& g) const;

 private:
  RigidTransform m_transform;
  Positions m_placed;
  Positions m_centered;               ///< y_i
  Positions m_rotated_reference;      ///< R^T s_i
  Eigen::Matrix3d m_rotation_inverse;  ///< (tr(S) I - S)^-1 (pseudo-inverse where S is degenerate)
};

}  // namespace balloon
