#include "design/objective_gauss_newton.hpp"

#include <utility>

namespace balloon {

ObjectiveGaussNewton::ObjectiveGaussNewton(Eigen::SparseMatrix<double, Eigen::RowMajor> distance_jacobian,
                                           Positions surface_normals, double surface_weight,
                                           std::shared_ptr<const ProcrustesPlacement> placement)
    : m_distance_jacobian(std::move(distance_jacobian)),
      m_surface_normals(std::move(surface_normals)),
      m_surface_weight(surface_weight),
      m_placement(std::move(placement)) {}

Eigen::VectorXd ObjectiveGaussNewton::operator()(const Eigen::VectorXd& v) const {
  const Eigen::VectorXd jv = m_distance_jacobian * v;
  Eigen::VectorXd out = 2.0 * (m_distance_jacobian.transpose() * jv);
  if (m_placement && m_surface_weight > 0.0) {
    const Eigen::VectorXd placed_v = m_placement->push_forward(v);
    Eigen::VectorXd surface(v.size());
    for (Eigen::Index i = 0; i < m_surface_normals.rows(); ++i) {
      const Eigen::Vector3d n = m_surface_normals.row(i).transpose();
      surface.segment<3>(3 * i) = (2.0 * m_surface_weight * n.dot(placed_v.segment<3>(3 * i))) * n;
    }
    out += m_placement->pull_back(surface);
  }
  return out;
}

}  // namespace balloon
