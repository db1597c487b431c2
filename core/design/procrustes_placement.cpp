#include "design/procrustes_placement.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace balloon {

ProcrustesPlacement::ProcrustesPlacement(const Positions& points, const Positions& reference_points)
    : m_transform(rigid_alignment(points, reference_points)), m_placed(m_transform.apply(points)) {
  const Eigen::RowVector3d center = points.colwise().mean();
  const Eigen::RowVector3d reference_center = reference_points.colwise().mean();
  m_centered = points.rowwise() - center;
  const Positions reference_centered = reference_points.rowwise() - reference_center;
  const Eigen::Matrix3d& rotation = m_transform.rotation;
  m_rotated_reference = reference_centered * rotation;  // rows R^T s_i
  const Eigen::Matrix3d m = reference_centered.transpose() * m_centered;
  Eigen::Matrix3d s = rotation.transpose() * m;
  s = 0.5 * (s + s.transpose());
  const Eigen::Matrix3d a = s.trace() * Eigen::Matrix3d::Identity() - s;
  // Symmetric; singular only for collinear points, whose rotation about their line is undetermined.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::Vector3d inverse_values = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    if (std::abs(eigen.eigenvalues()[k]) > 1e-12 * largest) inverse_values[k] = 1.0 / eigen.eigenvalues()[k];
  m_rotation_inverse = eigen.eigenvectors() * inverse_values.asDiagonal() * eigen.eigenvectors().transpose();
}

Eigen::VectorXd ProcrustesPlacement::push_forward(const Eigen::VectorXd& v) const {
  const Eigen::Map<const Positions> change(v.data(), v.size() / 3, 3);
  const Positions dy = change.rowwise() - change.colwise().mean();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < dy.rows(); ++i)
    a += dy.row(i).transpose().cross(m_rotated_reference.row(i).transpose());
  const Eigen::Vector3d omega = m_rotation_inverse * a;
  Eigen::VectorXd out(v.size());
  for (Eigen::Index i = 0; i < dy.rows(); ++i)
    out.segment<3>(3 * i) =
        m_transform.rotation * (dy.row(i).transpose() + omega.cross(m_centered.row(i).transpose()));
  return out;
}

Eigen::VectorXd ProcrustesPlacement::pull_back(const Eigen::VectorXd& g) const {
  const Eigen::Map<const Positions> gradient(g.data(), g.size() / 3, 3);
  const Positions rotated = gradient * m_transform.rotation;  // rows R^T g_i
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < rotated.rows(); ++i)
    b += m_centered.row(i).transpose().cross(rotated.row(i).transpose());
  const Eigen::Vector3d u = m_rotation_inverse * b;
  Positions h(rotated.rows(), 3);
  for (Eigen::Index i = 0; i < rotated.rows(); ++i)
    h.row(i) = rotated.row(i) + m_rotated_reference.row(i).cross(u.transpose());
  h.rowwise() -= h.colwise().mean();
  return Eigen::Map<const Eigen::VectorXd>(h.data(), h.size());
}

}  // namespace balloon
