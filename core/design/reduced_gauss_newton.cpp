#include "design/reduced_gauss_newton.hpp"

#include <cmath>

namespace balloon {

GaussNewtonDirection reduced_gauss_newton_direction(
    const AdjointSensitivity& sensitivity, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& hessian_x,
    const Eigen::VectorXd& gradient, const std::vector<bool>& rest_free, const Eigen::VectorXd& rest_volume_gradient,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& precondition, int max_iterations, double tolerance,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& hessian_rest) {
  Eigen::VectorXd w = rest_volume_gradient;
  for (int c = 0; c < w.size(); ++c)
    if (!rest_free[static_cast<size_t>(c)]) w[c] = 0.0;
  const double w_norm2 = w.squaredNorm();
  auto project = [&](Eigen::VectorXd d) {
    for (int c = 0; c < d.size(); ++c)
      if (!rest_free[static_cast<size_t>(c)]) d[c] = 0.0;
    if (w_norm2 > 0.0) d -= (d.dot(w) / w_norm2) * w;
    return d;
  };
  auto apply = [&](const Eigen::VectorXd& d) {
    Eigen::VectorXd dx;
    double dp = 0.0;
    sensitivity.linear_response(d, dx, dp);  // J d
    Eigen::VectorXd product = sensitivity.gradient(hessian_x(dx));  // J^T H J d
    if (hessian_rest) product += hessian_rest(d);
    return project(product);
  };

  GaussNewtonDirection out;
  out.direction = Eigen::VectorXd::Zero(gradient.size());
  Eigen::VectorXd residual = -project(gradient);
  const double residual0 = residual.norm();
  if (!(residual0 > 0.0) || !std::isfinite(residual0)) return out;
  Eigen::VectorXd z = project(precondition(residual));
  Eigen::VectorXd p = z;
  double rz = residual.dot(z);
  for (out.cg_iterations = 0; out.cg_iterations < max_iterations; ++out.cg_iterations) {
    const Eigen::VectorXd ap = apply(p);
    const double curvature = p.dot(ap);
    if (!(curvature > 0.0) || !std::isfinite(curvature)) {
      // Non-positive curvature along p (round-off in a near null direction of J): keep what CG has, or
      // the preconditioned gradient if it has nothing yet.
      if (out.cg_iterations == 0) out.direction = z;
      break;
    }
    const double alpha = rz / curvature;
    out.direction += alpha * p;
    residual -= alpha * ap;
    if (residual.norm() <= tolerance * residual0) {
      ++out.cg_iterations;
      break;
    }
    z = project(precondition(residual));
    const double rz_next = residual.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  out.descent = out.direction.allFinite() && out.direction.dot(gradient) < 0.0;
  if (!out.direction.allFinite()) out.direction.setZero();
  return out;
}

}  // namespace balloon
