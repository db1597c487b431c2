#include "solve/rigid_modes.hpp"

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

}  // namespace balloon
