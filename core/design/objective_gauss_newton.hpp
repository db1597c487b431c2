#pragma once
/// The design objective's Gauss-Newton Hessian in inflated coordinates, as an operator: 2 J^T J for E_dist
/// (J: the Jacobian of its least-squares residuals, 6 or 12 entries a row) plus 2 w n n^T per vertex for
/// E_surf (n: the normal of the target triangle closest to the vertex), E_surf taken at the shape's
/// Procrustes placement P(x) on the target: J_P^T (2 w n n^T) J_P. The reduced Gauss-Newton direction
/// only multiplies by it; assembling it as a matrix took about 2 million triplets per direction at 4,000
/// vertices, a quarter of a design's time.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

#include "design/procrustes_placement.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon {

class ObjectiveGaussNewton {
 public:
  /// `distance_jacobian`: dr/dx of E_dist's residuals (E_dist = |r|^2); `surface_normals`: #V unit normals
  /// (a zero row leaves that vertex out); `surface_weight`: w of E_surf = w sum_i d_i^2 (mm^-1).
  /// `placement`: P(x), in whose frame the normals are (null: no surface term).
  ObjectiveGaussNewton(Eigen::SparseMatrix<double, Eigen::RowMajor> distance_jacobian, Positions surface_normals,
                       double surface_weight, std::shared_ptr<const ProcrustesPlacement> placement);

  /// H v for a 3#V vector v.
  Eigen::VectorXd operator()(const Eigen::VectorXd& v) const;

 private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> m_distance_jacobian;
  Positions m_surface_normals;
  double m_surface_weight = 0.0;
  std::shared_ptr<const ProcrustesPlacement> m_placement;
};

}  // namespace balloon
