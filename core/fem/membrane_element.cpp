#include "fem/membrane_element.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "fem/second_order_jet.hpp"

namespace balloon::fem {
namespace {

struct EdgeGram {
  Eigen::Vector3d e1, e2;  // x2 - x1, x3 - x1
  double s11, s12, s22;
};

EdgeGram edge_gram(const Vector9d& x) {
  EdgeGram g;
  g.e1 = x.segment<3>(3) - x.segment<3>(0);
  g.e2 = x.segment<3>(6) - x.segment<3>(0);
  g.s11 = g.e1.dot(g.e1);
  g.s12 = g.e1.dot(g.e2);
  g.s22 = g.e2.dot(g.e2);
  return g;
}

/// d(s11, s12, s22)/d(x1, x2, x3): 3x9.
Eigen::Matrix<double, 3, 9> gram_jacobian(const EdgeGram& g) {
  Eigen::Matrix<double, 3, 9> J;
  J.setZero();
  J.block<1, 3>(0, 3) = 2.0 * g.e1.transpose();
  J.block<1, 3>(0, 0) = -2.0 * g.e1.transpose();
  J.block<1, 3>(1, 3) = g.e2.transpose();
  J.block<1, 3>(1, 6) = g.e1.transpose();
  J.block<1, 3>(1, 0) = -(g.e1 + g.e2).transpose();
  J.block<1, 3>(2, 6) = 2.0 * g.e2.transpose();
  J.block<1, 3>(2, 0) = -2.0 * g.e2.transpose();
  return J;
}

/// Where a triangle sits on Pipkin's relaxed energy (see membrane_element.hpp).
enum class TensionState { Taut, Wrinkled, Slack };

/// In-plane state from tr C and det C: taut when l1 l2^2 >= 1 (both principal stresses >= 0, by the
/// Baker-Ericksen inequality against the plane-stress direction l3 = 1/(l1 l2)), slack when l1 <= 1,
/// wrinkled between.
TensionState tension_state(double trace_c, double det_c) {
  const double largest = 0.5 * trace_c + std::sqrt(std::max(0.0, 0.25 * trace_c * trace_c - det_c));
  if (det_c >= std::sqrt(largest)) return TensionState::Taut;
  return largest <= 1.0 ? TensionState::Slack : TensionState::Wrinkled;
}

/// W = h * A_rest * Psi(I1, I2) as a function of the Gram entries (eq. 3, 4, 11):
/// tr C = tr(S M^-1), det C = det S / det M, I1 = tr C + 1/det C, I2 = det C + tr C / det C.
/// With `tension_field`, Pipkin's relaxed energy: a wrinkled triangle stores the energy of uniaxial
/// tension at its largest stretch l1 (l2 = l3 = l1^-1/2: I1 = l1^2 + 2/l1, I2 = 2 l1 + 1/l1^2), a slack
/// one none.
template <typename J>
J gram_energy(const Material& material, double thickness, const J& s11, const J& s12, const J& s22, const J& m11,
              const J& m12, const J& m22, bool tension_field = false) {
  const J det_m = m11 * m22 - m12 * m12;
  const J numerator = s11 * m22 - 2.0 * (s12 * m12) + s22 * m11;
  const J trace_c = numerator / det_m;
  const J det_s = s11 * s22 - s12 * s12;
  const J det_c = det_s / det_m;
  const TensionState state = tension_field ? tension_state(trace_c.v, det_c.v) : TensionState::Taut;
  J I1, I2;
  if (state == TensionState::Slack) {
    return J::constant(0.0);
  } else if (state == TensionState::Wrinkled) {
    // l1^2 = tr C / 2 + sqrt(tr C^2 / 4 - det C); the discriminant is bounded away from zero here
    // (l2^2 < 1/l1 < l1^2), and its curvature is multiplied by dPsi/dl1^2, which vanishes at l1 = 1.
    const J largest = 0.5 * trace_c + sqrt(0.25 * (trace_c * trace_c) - det_c);
    const J l1 = sqrt(largest);
    const J inv_l1 = inverse(l1);
    I1 = largest + 2.0 * inv_l1;
    I2 = 2.0 * l1 + inv_l1 * inv_l1;
  } else {
    const J inv_det_c = inverse(det_c);
    I1 = trace_c + inv_det_c;
    I2 = det_c + trace_c * inv_det_c;
  }
  const InvariantDerivatives d = strain_energy(material, I1.v, I2.v);
  const J psi = apply2(I1, I2, d.psi, d.d1, d.d2, d.d11, d.d12, d.d22);
  const J rest_area = 0.5 * sqrt(det_m);
  return thickness * (rest_area * psi);
}

bool collapsed(const EdgeGram& g) {
  const double det_s = g.s11 * g.s22 - g.s12 * g.s12;
  return !(det_s > 1e-24 * (g.s11 + g.s22) * (g.s11 + g.s22));
}

/// Every principal minor of the symmetric 2x2 or 3x3 `m` is non-negative: `m` is positive semi-definite.
template <int N>
bool principal_minors_nonnegative(const Eigen::Matrix<double, N, N>& m) {
  static_assert(N == 2 || N == 3, "closed form for 2x2 and 3x3 only");
  for (int i = 0; i < N; ++i)
    if (!(m(i, i) >= 0.0)) return false;
  for (int i = 0; i < N; ++i)
    for (int j = i + 1; j < N; ++j)
      if (!(m(i, i) * m(j, j) - m(i, j) * m(i, j) >= 0.0)) return false;
  return N == 2 || m.determinant() >= 0.0;
}

/// The nearest positive semi-definite matrix. Most clamped blocks already are (the uniaxial stress of a
/// wrinkled triangle, a neo-Hookean curvature): those are returned as they are, without the
/// eigen-decomposition, which took about 2% of a bent anchor's inflation.
template <int N>
Eigen::Matrix<double, N, N> clamp_eigenvalues(const Eigen::Matrix<double, N, N>& m) {
  if (principal_minors_nonnegative(m)) return m;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(m);
  const auto values = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

RestTriangle make_rest_triangle(const Vector9d& rest) {
  const EdgeGram g = edge_gram(rest);
  RestTriangle t;
  t.m11 = g.s11;
  t.m12 = g.s12;
  t.m22 = g.s22;
  t.area = 0.5 * std::sqrt(std::max(0.0, g.s11 * g.s22 - g.s12 * g.s12));
  return t;
}

bool is_relaxed(const RestTriangle& rest, const Vector9d& x) {
  const EdgeGram g = edge_gram(x);
  const double det_m = rest.m11 * rest.m22 - rest.m12 * rest.m12;
  const double trace_c = (g.s11 * rest.m22 - 2.0 * g.s12 * rest.m12 + g.s22 * rest.m11) / det_m;
  const double det_c = (g.s11 * g.s22 - g.s12 * g.s12) / det_m;
  return tension_state(trace_c, det_c) != TensionState::Taut;
}

double membrane_energy(const Material& material, double thickness, const RestTriangle& rest, const Vector9d& x,
                       bool tension_field) {
  const EdgeGram g = edge_gram(x);
  if (collapsed(g)) return std::numeric_limits<double>::infinity();
  const double det_m = rest.m11 * rest.m22 - rest.m12 * rest.m12;
  const double trace_c = (g.s11 * rest.m22 - 2.0 * g.s12 * rest.m12 + g.s22 * rest.m11) / det_m;
  const double det_c = (g.s11 * g.s22 - g.s12 * g.s12) / det_m;
  double I1 = trace_c + 1.0 / det_c;
  double I2 = det_c + trace_c / det_c;
  if (tension_field) {
    switch (tension_state(trace_c, det_c)) {
      case TensionState::Taut:
        break;
      case TensionState::Slack:
        return 0.0;
      case TensionState::Wrinkled: {
        const double largest = 0.5 * trace_c + std::sqrt(std::max(0.0, 0.25 * trace_c * trace_c - det_c));
        const double l1 = std::sqrt(largest);
        I1 = largest + 2.0 / l1;
        I2 = 2.0 * l1 + 1.0 / largest;
        break;
      }
    }
  }
  return thickness * rest.area * strain_energy(material, I1, I2).psi;
}

Vector9d membrane_gradient(const Material& material, double thickness, const RestTriangle& rest, const Vector9d& x,
                           bool tension_field) {
  // Residuals and line searches call this often: the 3-variable jet without its Hessian, no 9x9 products.
  const EdgeGram g = edge_gram(x);
  if (collapsed(g)) return Vector9d::Zero();
  using J3 = Jet<3, false>;
  const J3 w = gram_energy(material, thickness, J3::variable(g.s11, 0), J3::variable(g.s12, 1),
                           J3::variable(g.s22, 2), J3::constant(rest.m11), J3::constant(rest.m12),
                           J3::constant(rest.m22), tension_field);
  return gram_jacobian(g).transpose() * w.g;
}

void membrane_energy_gradient_hessian(const Material& material, double thickness, const RestTriangle& rest,
                                      const Vector9d& x, double& energy, Vector9d& gradient, Matrix9d& hessian,
                                      bool project_to_psd, bool tension_field) {
  const EdgeGram g = edge_gram(x);
  if (collapsed(g)) {
    energy = std::numeric_limits<double>::infinity();
    gradient.setZero();
    hessian.setZero();
    return;
  }
  using J3 = Jet<3>;
  const J3 w = gram_energy(material, thickness, J3::variable(g.s11, 0), J3::variable(g.s12, 1),
                           J3::variable(g.s22, 2), J3::constant(rest.m11), J3::constant(rest.m12),
                           J3::constant(rest.m22), tension_field);
  const Eigen::Matrix<double, 3, 9> js = gram_jacobian(g);
  energy = w.v;
  gradient = js.transpose() * w.g;

  // Material part: Js^T (d2W/ds2) Js. Geometric part: sum_k dW/ds_k * d2 s_k/dx2, which is
  // D^T (P kron I3) D with D mapping corners to the two edges.
  Eigen::Matrix3d material_curvature = w.h;
  Eigen::Matrix2d stress;
  stress << 2.0 * w.g[0], w.g[1], w.g[1], 2.0 * w.g[2];
  // A wrinkled triangle is kept positive semi-definite always: its stress is uniaxial tension (PSD), and
  // its energy is convex in C for neo-Hookean and the Hart-Smith presets (the clamp changes nothing);
  // an I2 term that makes the uniaxial energy concave at large stretch (Mooney-Rivlin) is clamped.
  if (project_to_psd || (tension_field && is_relaxed(rest, x))) {
    material_curvature = clamp_eigenvalues<3>(material_curvature);
    stress = clamp_eigenvalues<2>(stress);
  }
  // Coefficient-wise products: at 9x3x9 Eigen would otherwise take its blocked GEMM path (pack, kernel,
  // unpack; 1% of a bent anchor's inflation) for 243 multiplications.
  const Eigen::Matrix<double, 9, 3> jacobian_t_curvature = js.transpose().lazyProduct(material_curvature);
  hessian.noalias() = jacobian_t_curvature.lazyProduct(js);
  Eigen::Matrix<double, 2, 3> edges_of_corners;
  edges_of_corners << -1, 1, 0, -1, 0, 1;
  const Eigen::Matrix3d corner_coupling = edges_of_corners.transpose() * stress * edges_of_corners;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) hessian.block<3, 3>(3 * a, 3 * b).diagonal().array() += corner_coupling(a, b);
}

Matrix9d membrane_mixed_derivative(const Material& material, double thickness, const Vector9d& rest,
                                   const Vector9d& x, bool tension_field) {
  const EdgeGram g = edge_gram(x);
  const EdgeGram m = edge_gram(rest);
  using J6 = Jet<6>;
  const J6 w = gram_energy(material, thickness, J6::variable(g.s11, 0), J6::variable(g.s12, 1),
                           J6::variable(g.s22, 2), J6::variable(m.s11, 3), J6::variable(m.s12, 4),
                           J6::variable(m.s22, 5), tension_field);
  // gradient_x = Js(x)^T dW/ds(s, m(rest)), so d/d(rest) = Js^T d2W/(ds dm) Jm.
  return gram_jacobian(g).transpose() * w.h.block<3, 3>(0, 3) * gram_jacobian(m);
}

Eigen::Vector2d principal_stretches_squared(const RestTriangle& rest, const Vector9d& x) {
  const EdgeGram g = edge_gram(x);
  const double det_m = rest.m11 * rest.m22 - rest.m12 * rest.m12;
  const double trace_c = (g.s11 * rest.m22 - 2.0 * g.s12 * rest.m12 + g.s22 * rest.m11) / det_m;
  const double det_c = (g.s11 * g.s22 - g.s12 * g.s12) / det_m;
  const double disc = std::sqrt(std::max(0.0, 0.25 * trace_c * trace_c - det_c));
  return {0.5 * trace_c - disc, 0.5 * trace_c + disc};
}

}  // namespace balloon::fem
