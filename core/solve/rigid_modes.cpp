#include "solve/rigid_modes.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/QR>

namespace balloon {

std::vector<int> rigid_support_coordinates(const Positions& positions) {
  const Eigen::Index n = positions.rows();
  const Eigen::RowVector3d center = positions.colwise().mean();
  const double scale = std::max(1e-12, (positions.rowwise() - center).rowwise().norm().maxCoeff());
  // Rows: 3 translations and 3 rotations (about the centroid, scaled to unit lever arm).
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(6, 3 * n);
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Vector3d r = (positions.row(v) - center).transpose() / scale;
    for (int a = 0; a < 3; ++a) {
      modes(a, 3 * v + a) = 1.0;
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(a);
      const Eigen::Vector3d velocity = axis.cross(r);
      modes.block(3 + a, 3 * v, 1, 3) = velocity.transpose();
    }
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(modes);
  std::vector<int> chosen;
  for (int k = 0; k < 6 && k < 3 * n; ++k) chosen.push_back(static_cast<int>(qr.colsPermutation().indices()[k]));
  return chosen;
}

namespace {

/// Velocity of coordinate `c` under rigid mode `mode` (0-2 translations, 3-5 rotations about `center`).
double mode_velocity(const Eigen::VectorXd& x, const Eigen::Vector3d& center, int c, int mode) {
  const int axis = c % 3;
  if (mode < 3) return mode == axis ? 1.0 : 0.0;
  const Eigen::Vector3d r = x.segment<3>(c - axis) - center;
  return Eigen::Vector3d::Unit(mode - 3).cross(r)[axis];
}

Eigen::Vector3d centroid(const Eigen::VectorXd& x) {
  return x.reshaped(3, x.size() / 3).rowwise().mean();
}

}  // namespace

Eigen::VectorXd without_rigid_motion(const Eigen::VectorXd& x, const Eigen::VectorXd& step) {
  const Eigen::Index n = x.size() / 3;
  if (n == 0) return step;
  const Eigen::Vector3d center = centroid(x);
  // Normal equations of the 6 rigid modes: a 6 x 6 Gram matrix, O(#V).
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> projection = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 3, 6> block;
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Vector3d r = x.segment<3>(3 * v) - center;
    block.leftCols<3>().setIdentity();
    for (int a = 0; a < 3; ++a) block.col(3 + a) = Eigen::Vector3d::Unit(a).cross(r);
    gram += block.transpose() * block;
    projection += block.transpose() * step.segment<3>(3 * v);
  }
  const Eigen::Matrix<double, 6, 1> motion = gram.ldlt().solve(projection);
  Eigen::VectorXd result = step;
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Vector3d r = x.segment<3>(3 * v) - center;
    result.segment<3>(3 * v) -= motion.head<3>() + motion.tail<3>().cross(r);
  }
  return result;
}

void restore_rigid_support(Eigen::VectorXd& x, const Eigen::VectorXd& held, const std::vector<int>& support) {
  if (support.size() != 6) return;
  // Newton on the six support equations over (translation, rotation vector); quadratic, so three
  // corrections bring a rigid drift of a few degrees to round-off.
  for (int pass = 0; pass < 4; ++pass) {
    const Eigen::Vector3d center = centroid(x);
    Eigen::Matrix<double, 6, 6> jacobian;
    Eigen::Matrix<double, 6, 1> gap;
    for (int i = 0; i < 6; ++i) {
      gap[i] = held[support[i]] - x[support[i]];
      for (int mode = 0; mode < 6; ++mode) jacobian(i, mode) = mode_velocity(x, center, support[i], mode);
    }
    if (gap.norm() <= 1e-13 * (1.0 + held.cwiseAbs().maxCoeff())) return;
    const Eigen::Matrix<double, 6, 1> motion = jacobian.colPivHouseholderQr().solve(gap);
    if (!motion.allFinite()) return;
    const Eigen::Vector3d omega = motion.tail<3>();
    const double angle = omega.norm();
    const Eigen::Matrix3d rotation =
        angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
    for (Eigen::Index v = 0; v < x.size() / 3; ++v)
      x.segment<3>(3 * v) = center + rotation * (x.segment<3>(3 * v) - center) + motion.head<3>();
  }
}

}  // namespace balloon
