#include "design/adjoint_sensitivity.hpp"

#include <cmath>

namespace balloon {

AdjointSensitivity::AdjointSensitivity(const fem::BalloonModel& model, EquilibriumSolver& solver)
    : m_model(model), m_solver(solver) {}

bool AdjointSensitivity::prepare(const Eigen::VectorXd& rest, const Eigen::VectorXd& x, double pressure_mpa) {
  if (!m_solver.factorize_exact(x, pressure_mpa)) return false;
  m_volume_gradient = m_model.volume_gradient(x);
  m_volume_response = m_solver.solve_with_factorization(m_volume_gradient);
  m_mixed = mixed_blocks(rest, x);
  return std::abs(volume_per_pressure()) > 0.0 && m_volume_response.allFinite();
}

Eigen::VectorXd AdjointSensitivity::gradient(const Eigen::VectorXd& objective_gradient_x) const {
  const Eigen::VectorXd& v = m_volume_gradient;
  const Eigen::VectorXd& b = m_volume_response;
  // lambda solves the bordered system's adjoint: K lambda = dJ/dx - mu v with v^T lambda = 0.
  const Eigen::VectorXd a = m_solver.solve_with_factorization(objective_gradient_x);
  const Eigen::VectorXd lambda = a - (v.dot(a) / volume_per_pressure()) * b;
  return -apply_mixed(m_mixed, lambda, true);
}

void AdjointSensitivity::linear_response(const Eigen::VectorXd& direction, Eigen::VectorXd& dx, double& dp) const {
  const Eigen::VectorXd& v = m_volume_gradient;
  const Eigen::VectorXd& b = m_volume_response;
  const Eigen::VectorXd a = m_solver.solve_with_factorization(-apply_mixed(m_mixed, direction, false));
  const double vb = volume_per_pressure();
  dp = std::abs(vb) > 0.0 ? -v.dot(a) / vb : 0.0;
  dx = a + dp * b;
  if (!dx.allFinite()) {
    dx.setZero(direction.size());
    dp = 0.0;
  }
}

Eigen::VectorXd AdjointSensitivity::mixed_product(const Eigen::VectorXd& rest, const Eigen::VectorXd& x,
                                                  const Eigen::VectorXd& s, bool transpose) const {
  return apply_mixed(mixed_blocks(rest, x), s, transpose);
}

AdjointSensitivity::MixedBlocks AdjointSensitivity::mixed_blocks(const Eigen::VectorXd& rest,
                                                                 const Eigen::VectorXd& x) const {
  MixedBlocks blocks;
  const Faces& faces = m_model.faces();
  blocks.triangles.resize(static_cast<size_t>(faces.rows()));
  for (int f = 0; f < faces.rows(); ++f)
    blocks.triangles[static_cast<size_t>(f)] = fem::membrane_mixed_derivative(
        m_model.material(), m_model.thickness(f), m_model.corners(rest, f), m_model.corners(x, f));
  // The sheet's bending hinges, when on: their rest angles and stiffnesses move with the rest shape too.
  const int hinge_count = static_cast<int>(m_model.hinges().size());
  blocks.hinges.resize(static_cast<size_t>(hinge_count));
  for (int h = 0; h < hinge_count; ++h)
    blocks.hinges[static_cast<size_t>(h)] =
        fem::hinge_mixed_derivative(m_model.rest_hinge(h), m_model.hinge_corners(rest, h), m_model.hinge_corners(x, h));
  return blocks;
}

Eigen::VectorXd AdjointSensitivity::apply_mixed(const MixedBlocks& blocks, const Eigen::VectorXd& s,
                                                bool transpose) const {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(s.size());
  const Faces& faces = m_model.faces();
  for (int f = 0; f < faces.rows(); ++f) {
    const fem::Matrix9d& mixed = blocks.triangles[static_cast<size_t>(f)];
    const fem::Vector9d corners = m_model.corners(s, f);
    const fem::Vector9d product = transpose ? fem::Vector9d(mixed.transpose() * corners) : fem::Vector9d(mixed * corners);
    for (int k = 0; k < 3; ++k) out.segment<3>(3 * faces(f, k)) += product.segment<3>(3 * k);
  }
  const auto& hinges = m_model.hinges();
  for (size_t h = 0; h < blocks.hinges.size(); ++h) {
    const fem::Matrix12d& mixed = blocks.hinges[h];
    const fem::Vector12d corners = m_model.hinge_corners(s, static_cast<int>(h));
    const fem::Vector12d product = transpose ? fem::Vector12d(mixed.transpose() * corners) : fem::Vector12d(mixed * corners);
    for (int k = 0; k < 4; ++k) out.segment<3>(3 * hinges[h][static_cast<size_t>(k)]) += product.segment<3>(3 * k);
  }
  return out;
}

}  // namespace balloon
