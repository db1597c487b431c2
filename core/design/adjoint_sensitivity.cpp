#include "design/adjoint_sensitivity.hpp"

#include <cmath>

#include "fem/hinge_bending.hpp"
#include "fem/membrane_element.hpp"

namespace balloon {

AdjointSensitivity::AdjointSensitivity(const fem::BalloonModel& model, EquilibriumSolver& solver)
    : m_model(model), m_solver(solver) {}

bool AdjointSensitivity::prepare(const Eigen::VectorXd& rest, const Eigen::VectorXd& x, double pressure_mpa) {
  m_rest = rest;
  m_x = x;
  if (!m_solver.factorize_exact(x, pressure_mpa)) return false;
  m_volume_gradient = m_model.volume_gradient(x);
  m_volume_response = m_solver.solve_with_factorization(m_volume_gradient);
  return std::abs(m_volume_gradient.dot(m_volume_response)) > 0.0 && m_volume_response.allFinite();
}

Eigen::VectorXd AdjointSensitivity::gradient(const Eigen::VectorXd& objective_gradient_x) const {
  const Eigen::VectorXd& v = m_volume_gradient;
  const Eigen::VectorXd& b = m_volume_response;
  // lambda solves the bordered system's adjoint: K lambda = dJ/dx - mu v with v^T lambda = 0.
  const Eigen::VectorXd a = m_solver.solve_with_factorization(objective_gradient_x);
  const Eigen::VectorXd lambda = a - (v.dot(a) / v.dot(b)) * b;
  return -mixed_product(m_rest, m_x, lambda, true);
}

void AdjointSensitivity::linear_response(const Eigen::VectorXd& direction, Eigen::VectorXd& dx, double& dp) const {
  const Eigen::VectorXd& v = m_volume_gradient;
  const Eigen::VectorXd& b = m_volume_response;
  const Eigen::VectorXd a = m_solver.solve_with_factorization(-mixed_product(m_rest, m_x, direction, false));
  const double vb = v.dot(b);
  dp = std::abs(vb) > 0.0 ? -v.dot(a) / vb : 0.0;
  dx = a + dp * b;
  if (!dx.allFinite()) {
    dx.setZero(m_rest.size());
    dp = 0.0;
  }
}

Eigen::VectorXd AdjointSensitivity::mixed_product(const Eigen::VectorXd& rest, const Eigen::VectorXd& x,
                                                  const Eigen::VectorXd& s, bool transpose) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(rest.size());
  const Faces& faces = m_model.faces();
  for (int f = 0; f < faces.rows(); ++f) {
    const fem::Matrix9d mixed = fem::membrane_mixed_derivative(m_model.material(), m_model.thickness(f),
                                                               m_model.corners(rest, f), m_model.corners(x, f));
    const fem::Vector9d corners = m_model.corners(s, f);
    const fem::Vector9d product = transpose ? fem::Vector9d(mixed.transpose() * corners) : fem::Vector9d(mixed * corners);
    for (int k = 0; k < 3; ++k) out.segment<3>(3 * faces(f, k)) += product.segment<3>(3 * k);
  }
  // The sheet's bending hinges, when on: their rest angles and stiffnesses move with the rest shape too.
  const auto& hinges = m_model.hinges();
  for (int h = 0; h < static_cast<int>(hinges.size()); ++h) {
    const fem::Matrix12d mixed =
        fem::hinge_mixed_derivative(m_model.rest_hinge(h), m_model.hinge_corners(rest, h), m_model.hinge_corners(x, h));
    const fem::Vector12d corners = m_model.hinge_corners(s, h);
    const fem::Vector12d product = transpose ? fem::Vector12d(mixed.transpose() * corners) : fem::Vector12d(mixed * corners);
    for (int k = 0; k < 4; ++k) out.segment<3>(3 * hinges[static_cast<size_t>(h)][static_cast<size_t>(k)]) += product.segment<3>(3 * k);
  }
  return out;
}

}  // namespace balloon
