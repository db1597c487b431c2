#include "design/rest_hinge_fold.hpp"

#include <cmath>
#include <limits>

namespace balloon {

RestHingeFold::RestHingeFold(const DistanceEnergy& start, double weight)
    : m_hinges(start.edges().topRows(start.hinge_count())),
      m_start_angles(start.rest_angles()),
      m_weights(start.rest_lengths().head(start.hinge_count())) {
  const double total = start.rest_lengths().sum();
  m_weights *= weight / std::max(total, std::numeric_limits<double>::min());
}

Eigen::Vector3d RestHingeFold::corner(const Eigen::VectorXd& rest, int hinge, int k) const {
  return rest.segment<3>(3 * m_hinges(hinge, k));
}

double RestHingeFold::signed_turn(const Eigen::VectorXd& rest, int hinge) const {
  const double angle = dihedral_angle(corner(rest, hinge, 0), corner(rest, hinge, 1), corner(rest, hinge, 2),
                                      corner(rest, hinge, 3));
  return std::remainder(angle - m_start_angles[hinge], 2.0 * M_PI);
}

double RestHingeFold::turn(const Eigen::VectorXd& rest, int hinge) const { return std::abs(signed_turn(rest, hinge)); }

double RestHingeFold::ratio_and_gradient(const Eigen::VectorXd& rest, int hinge, Vector12d* gradient) const {
  const double turned = signed_turn(rest, hinge);
  const double d = std::abs(turned);
  if (!(d > THRESHOLD)) return 0.0;
  if (!(d < M_PI)) return std::numeric_limits<double>::infinity();
  const double ratio = (d - THRESHOLD) / (M_PI - d);
  if (gradient) {
    // dr/dd = (pi - THRESHOLD) / (pi - d)^2, and dd/dtheta = sign of the turn.
    const double slope = (M_PI - THRESHOLD) / ((M_PI - d) * (M_PI - d)) * (turned < 0.0 ? -1.0 : 1.0);
    *gradient = slope * dihedral_angle_gradient(corner(rest, hinge, 0), corner(rest, hinge, 1),
                                                corner(rest, hinge, 2), corner(rest, hinge, 3));
  }
  return ratio;
}

double RestHingeFold::value(const Eigen::VectorXd& rest) const {
  double value = 0.0;
  for (int h = 0; h < m_hinges.rows(); ++h) {
    const double ratio = ratio_and_gradient(rest, h, nullptr);
    if (ratio > 0.0) value += m_weights[h] * ratio * ratio;
  }
  return value;
}

void RestHingeFold::add_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const {
  Vector12d ratio_gradient;
  for (int h = 0; h < m_hinges.rows(); ++h) {
    const double ratio = ratio_and_gradient(rest, h, &ratio_gradient);
    if (!(ratio > 0.0) || !std::isfinite(ratio)) continue;  // at a full fold the value is infinite already
    for (int k = 0; k < 4; ++k)
      gradient.segment<3>(3 * m_hinges(h, k)) += 2.0 * m_weights[h] * ratio * ratio_gradient.segment<3>(3 * k);
  }
}

Eigen::VectorXd RestHingeFold::gauss_newton_times(const Eigen::VectorXd& rest, const Eigen::VectorXd& direction) const {
  Eigen::VectorXd product = Eigen::VectorXd::Zero(rest.size());
  Vector12d ratio_gradient;
  for (int h = 0; h < m_hinges.rows(); ++h) {
    const double ratio = ratio_and_gradient(rest, h, &ratio_gradient);
    if (!(ratio > 0.0) || !std::isfinite(ratio)) continue;
    double along = 0.0;
    for (int k = 0; k < 4; ++k) along += ratio_gradient.segment<3>(3 * k).dot(direction.segment<3>(3 * m_hinges(h, k)));
    for (int k = 0; k < 4; ++k)
      product.segment<3>(3 * m_hinges(h, k)) += 2.0 * m_weights[h] * along * ratio_gradient.segment<3>(3 * k);
  }
  return product;
}

int RestHingeFold::folded_count(const Eigen::VectorXd& rest) const {
  int count = 0;
  for (int h = 0; h < m_hinges.rows(); ++h)
    if (turn(rest, h) > THRESHOLD) ++count;
  return count;
}

}  // namespace balloon
