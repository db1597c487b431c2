#include "solve/rigid_modes.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/QR>

namespace balloon {
namespace {

/// The velocities of a point at `r` from the centre under the six rigid modes: columns 0-2 translate
/// along x, y, z; columns 3-5 rotate about them (velocity e_a x r).
Eigen::Matrix<double, 3, 6> rigid_mode_velocities(const Eigen::Vector3d& r) {
  Eigen::Matrix<double, 3, 6> velocities;
  velocities.leftCols<3>().setIdentity();
  for (int a = 0; a < 3; ++a) velocities.col(3 + a) = Eigen::Vector3d::Unit(a).cross(r);
  return velocities;
}

Eigen::Vector3d centroid(const Eigen::VectorXd& x) {
  return x.reshaped(3, x.size() / 3).rowwise().mean();
}

}  // namespace

std::vector<int> rigid_support_coordinates(const Positions& positions) {
  const Eigen::Index n = positions.rows();
  const Eigen::RowVector3d center = positions.colwise().mean();
  const double scale = std::max(1e-12, (positions.rowwise() - center).rowwise().norm().maxCoeff());
  // Rows: 3 translations and 3 rotations (about the centroid, scaled to unit lever arm).
  Eigen::MatrixXd modes(6, 3 * n);
  for (Eigen::Index v = 0; v < n; ++v)
    modes.middleCols<3>(3 * v) = rigid_mode_velocities((positions.row(v) - center).transpose() / scale).transpose();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(modes);
  std::vector<int> chosen;
  for (int k = 0; k < 6 && k < 3 * n; ++k) chosen.push_back(static_cast<int>(qr.colsPermutation().indices()[k]));
  return chosen;
}

Eigen::VectorXd without_rigid_motion(const Eigen::VectorXd& x, const Eigen::VectorXd& step) {
  const Eigen::Index n = x.size() / 3;
  if (n == 0) return step;
  const Eigen::Vector3d center = centroid(x);
  // Normal equations of the 6 rigid modes: a 6 x 6 Gram matrix, O(#V).
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> projection = Eigen::Matrix<double, 6, 1>::Zero();
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Matrix<double, 3, 6> block = rigid_mode_velocities(x.segment<3>(3 * v) - center);
    gram += block.transpose() * block;
    projection += block.transpose() * step.segment<3>(3 * v);
  }
  const Eigen::Matrix<double, 6, 1> motion = gram.ldlt().solve(projection);
  Eigen::VectorXd result = step;
  for (Eigen::Index v = 0; v < n; ++v) result.segment<3>(3 * v) -= rigid_mode_velocities(x.segment<3>(3 * v) - center) * motion;
  return result;
}

bool restore_rigid_support(Eigen::VectorXd& x, const Eigen::VectorXd& held, const std::vector<int>& support) {
  if (support.size() != 6) return false;
  // Newton on the six support equations over (translation, rotation vector); quadratic, so three
  // corrections bring a rigid drift of a few degrees to round-off.
  bool moved = false;
  for (int pass = 0; pass < 4; ++pass) {
    const Eigen::Vector3d center = centroid(x);
    Eigen::Matrix<double, 6, 6> jacobian;
    Eigen::Matrix<double, 6, 1> gap;
    for (int i = 0; i < 6; ++i) {
      const int c = support[i], axis = c % 3;
      gap[i] = held[c] - x[c];
      jacobian.row(i) = rigid_mode_velocities(x.segment<3>(c - axis) - center).row(axis);
    }
    if (gap.norm() <= 1e-13 * (1.0 + held.cwiseAbs().maxCoeff())) return moved;
    const Eigen::Matrix<double, 6, 1> motion = jacobian.colPivHouseholderQr().solve(gap);
    if (!motion.allFinite()) return moved;
    const Eigen::Vector3d omega = motion.tail<3>();
    const double angle = omega.norm();
    const Eigen::Matrix3d rotation =
        angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
    for (Eigen::Index v = 0; v < x.size() / 3; ++v)
      x.segment<3>(3 * v) = center + rotation * (x.segment<3>(3 * v) - center) + motion.head<3>();
    moved = true;
  }
  return moved;
}

}  // namespace balloon
