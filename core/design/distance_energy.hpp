#pragma once
/// Discrete-shell distance between two shapes on one connectivity (paper eq. 18), with its gradient,
/// Hessian and least-squares residuals. With the target as reference it is the design objective E_dist;
/// with the initial rest shape as reference and k_length = 0 it is the rest-shape bending regularizer.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// Signed dihedral angle (rad, in (-pi, pi]) of the hinge x0-x1 between triangles (x0, x1, x2) and
/// (x1, x0, x3), both counter-clockwise seen from outside: the angle from the normal of the first to the
/// normal of the second about the axis x1 - x0, computed as atan2(sin, cos) so it is smooth through
/// flat (0). Positive where the surface is convex (every hinge of a sphere), negative where concave.
double dihedral_angle(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                      const Eigen::Vector3d& x3);
/// Gradient (rad/mm) of dihedral_angle with respect to (x0, x1, x2, x3) stacked. Zero for a degenerate
/// (zero-area) triangle, where the angle is undefined.
Vector12d dihedral_angle_gradient(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                  const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);
/// Exact Hessian (rad/mm^2, symmetric 12x12) of dihedral_angle with respect to (x0, x1, x2, x3) stacked.
Matrix12d dihedral_angle_hessian(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                 const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);

/// Which second derivative DistanceEnergy::hessian_triplets assembles.
enum class DistanceHessian {
  Exact,           ///< the true Hessian (indefinite away from the reference)
  ProjectedExact,  ///< per-edge exact Hessian with negative eigenvalues clamped to 0 (PSD)
  GaussNewton,     ///< 2 * sum_r grad r grad r^T over the residuals (PSD, exact at the reference)
};

/// E_dist(x) = sum_e [k_l (1 - l_e/l0_e)^2 + k_b (theta_e - theta0_e)^2] l0_e   (eq. 18)
/// over the edges e of a closed or open, consistently oriented, edge-manifold mesh; the bending term
/// runs over interior edges only. l0, theta0 come from the reference shape given at construction.
/// Units: k_l dimensionless, k_b per rad^2, so E_dist is in mm (length-weighted).
/// Precompute once per (reference, faces); value/gradient/Hessian are then O(#E), single-threaded.
class DistanceEnergy {
 public:
  /// Default stiffnesses k_l = k_b = 1: a 100% edge strain costs as much as a 1 rad hinge-angle error,
  /// both per mm of reference edge. Both terms are then invariant to the mesh scale up to the l0 weight,
  /// so E_dist / (total reference edge length) is a dimensionless shape error.
  static constexpr double DEFAULT_K_LENGTH = 1.0;
  static constexpr double DEFAULT_K_BENDING = 1.0;

  /// reference: #V by 3 reference positions (mm); faces: #F by 3, counter-clockwise seen from outside;
  /// k_length >= 0 (dimensionless), k_bending >= 0 (1/rad^2). Either may be 0 (e.g. k_length = 0 for the
  /// bending regularizer). Throws std::invalid_argument on a non-manifold or inconsistently oriented
  /// edge, a negative stiffness, or a zero-length reference edge.
  DistanceEnergy(const Positions& reference, const Faces& faces, double k_length = DEFAULT_K_LENGTH,
                 double k_bending = DEFAULT_K_BENDING);

  int vertex_count() const { return m_vertex_count; }
  /// Number of undirected edges (length terms).
  int edge_count() const { return static_cast<int>(m_edges.rows()); }
  /// Number of interior edges (bending terms).
  int hinge_count() const { return m_hinge_count; }
  /// #E by 4: (v0, v1, opposite in the face holding v0->v1, opposite in the face holding v1->v0);
  /// the last is -1 on a boundary edge. Interior edges come first, in the order of the hinge residuals.
  const Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>& edges() const { return m_edges; }
  /// #E reference edge lengths l0 (mm).
  const Eigen::VectorXd& rest_lengths() const { return m_rest_lengths; }
  /// #hinges reference dihedral angles theta0 (rad), see dihedral_angle().
  const Eigen::VectorXd& rest_angles() const { return m_rest_angles; }
  double k_length() const { return m_k_length; }
  double k_bending() const { return m_k_bending; }

  /// E_dist (mm) at x (3#V flat positions, mm).
  double value(Eigen::Ref<const Eigen::VectorXd> x) const;
  /// The two parts of value(): sum of length terms and sum of bending terms (mm).
  Eigen::Vector2d value_parts(Eigen::Ref<const Eigen::VectorXd> x) const;
  /// dE/dx (3#V, dimensionless): `gradient` is resized and overwritten.
  void gradient(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& gradient) const;
  /// Appends the Hessian (1/mm) entries to `triplets`, rows/cols shifted by dof_offset (for stacked
  /// unknowns such as (rest, deformed) in the augmented Lagrangian). Duplicates are meant to be summed.
  void hessian_triplets(Eigen::Ref<const Eigen::VectorXd> x, std::vector<Eigen::Triplet<double>>& triplets,
                        DistanceHessian kind = DistanceHessian::Exact, int dof_offset = 0) const;
  /// How many entries hessian_triplets appends (at most).
  size_t hessian_entry_count() const;
  /// The Hessian as a 3#V by 3#V sparse matrix (convenience over hessian_triplets).
  Eigen::SparseMatrix<double> hessian(Eigen::Ref<const Eigen::VectorXd> x,
                                      DistanceHessian kind = DistanceHessian::Exact) const;

  /// Number of least-squares residuals: #E length residuals if k_length > 0, then #hinges bending
  /// residuals if k_bending > 0, so that value(x) = |r(x)|^2.
  int residual_count() const;
  /// r (sqrt(mm)): length r_e = sqrt(k_l l0) (1 - l/l0) per edge in edges() order, then bending
  /// r_h = sqrt(k_b l0) (theta - theta0) per interior edge (angle difference wrapped into (-pi, pi]).
  void residuals(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& residuals) const;
  /// Appends the Jacobian dr/dx (residual_count by 3#V, 1/sqrt(mm)) entries to `triplets`; columns are
  /// shifted by dof_offset. Each length row has 6 entries, each bending row 12.
  void residual_jacobian_triplets(Eigen::Ref<const Eigen::VectorXd> x,
                                  std::vector<Eigen::Triplet<double>>& triplets, int dof_offset = 0) const;

 private:
  int m_vertex_count = 0;
  int m_hinge_count = 0;
  double m_k_length = 0.0;
  double m_k_bending = 0.0;
  Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor> m_edges;
  Eigen::VectorXd m_rest_lengths;
  Eigen::VectorXd m_rest_angles;
};

}  // namespace balloon
