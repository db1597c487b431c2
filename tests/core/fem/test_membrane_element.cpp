// Finite-difference checks of the membrane element: gradient against the energy, Hessian and the
// mixed rest derivative against the analytic gradient, for every material, including stiff and
// near-degenerate cases.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "core/central_differences.hpp"
#include "fem/membrane_element.hpp"

namespace balloon::fem {
namespace {

struct Case {
  const char* label;
  Material material;
  double stretch;  // equibiaxial stretch applied to the rest triangle before a random perturbation
  bool sliver;     // near-degenerate rest triangle
};

Material make(MaterialModel model, double a, double b = 0, double c = 0) {
  Material m;
  m.model = model;
  m.params = {a, b, c};
  return m;
}

std::vector<Case> cases() {
  return {
      {"neo-hookean", make(MaterialModel::NeoHookean, 0.3), 1.5, false},
      {"neo-hookean-compressed", make(MaterialModel::NeoHookean, 0.3), 0.8, false},
      {"mooney-rivlin", make(MaterialModel::MooneyRivlin, 0.18, 0.02), 2.0, false},
      {"hart-smith", make(MaterialModel::HartSmith, 0.1, 3e-4, 1.0), 2.5, false},
      {"hart-smith-stiff-k1-1e-2-stretch-4", make(MaterialModel::HartSmith, 0.1, 1e-2, 1.0), 4.0, false},
      {"hart-smith-sliver", make(MaterialModel::HartSmith, 0.1, 3e-4, 1.0), 1.8, true},
      {"neo-hookean-sliver", make(MaterialModel::NeoHookean, 0.3), 1.3, true},
  };
}

Vector9d rest_triangle(std::mt19937& rng, bool sliver) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector9d r;
  r << 0, 0, 0, 2.0 + 0.3 * u(rng), 0.2 * u(rng), 0.1 * u(rng), 0.8 + 0.2 * u(rng), 1.5 + 0.2 * u(rng), 0.2 * u(rng);
  if (sliver) r.segment<3>(6) = 0.5 * r.segment<3>(3) + Eigen::Vector3d(0.0, 1e-3, 2e-4);  // angle ~0.05 deg
  return r;
}

/// A rotated, stretched copy of the rest triangle with a perturbation small against its smallest height,
/// so that slivers stay slivers (a sliver opened up by 50x would overflow Hart-Smith's exponential).
Vector9d deformed_triangle(std::mt19937& rng, const Vector9d& rest, double stretch) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d e1 = rest.segment<3>(3) - rest.segment<3>(0), e2 = rest.segment<3>(6) - rest.segment<3>(0);
  const double height = e1.cross(e2).norm() / std::max({e1.norm(), e2.norm(), (e2 - e1).norm()});
  const double noise = std::min(0.05, 0.05 * height);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Vector9d x;
  for (int k = 0; k < 3; ++k)
    x.segment<3>(3 * k) = rotation * (stretch * rest.segment<3>(3 * k)) + noise * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return x;
}

/// Five rest triangles of the case's kind, each with its deformed copy and its rest data, drawn from `seed`.
struct Trial {
  Vector9d rest, x;
  RestTriangle r;
};
std::vector<Trial> trials(const Case& c, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Trial> all;
  for (int k = 0; k < 5; ++k) {
    Trial t;
    t.rest = rest_triangle(rng, c.sliver);
    t.x = deformed_triangle(rng, t.rest, c.stretch);
    t.r = make_rest_triangle(t.rest);
    all.push_back(t);
  }
  return all;
}

double relative_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(a.norm(), b.norm());
}

class MembraneElementTest : public ::testing::TestWithParam<Case> {};

TEST_P(MembraneElementTest, GradientMatchesFiniteDifferencesOfEnergy) {
  const Case c = GetParam();
  const std::vector<Trial> all = trials(c, 7);
  for (size_t trial = 0; trial < all.size(); ++trial) {
    const auto& [rest, x, r] = all[trial];
    const Vector9d analytic = membrane_gradient(c.material, 0.5, r, x);
    const double step = 1e-6 * x.norm() * (c.sliver ? 1e-2 : 1.0);
    const Vector9d numeric = test::central_difference_gradient(
        [&](const Vector9d& y) { return membrane_energy(c.material, 0.5, r, y); }, x, step);
    ASSERT_GT(analytic.norm(), 1e-10) << c.label;
    // A sliver's energy carries cancellation error (det M ~ 1e-6), which the difference quotient amplifies.
    EXPECT_LT(relative_error(analytic, numeric), c.sliver ? 1e-4 : 1e-6) << c.label << " trial " << trial;
  }
}

TEST_P(MembraneElementTest, HessianMatchesFiniteDifferencesOfGradient) {
  const Case c = GetParam();
  const std::vector<Trial> all = trials(c, 11);
  for (size_t trial = 0; trial < all.size(); ++trial) {
    const auto& [rest, x, r] = all[trial];
    double energy;
    Vector9d gradient;
    Matrix9d analytic;
    membrane_energy_gradient_hessian(c.material, 0.5, r, x, energy, gradient, analytic);
    const double step = 1e-6 * x.norm() * (c.sliver ? 1e-2 : 1.0);
    const Matrix9d numeric = test::central_difference_jacobian(
        [&](const Vector9d& y) { return membrane_gradient(c.material, 0.5, r, y); }, x, step);
    ASSERT_GT(analytic.norm(), 1e-10) << c.label;
    EXPECT_LT(relative_error(analytic, numeric), 1e-5) << c.label << " trial " << trial;
    EXPECT_LT((analytic - analytic.transpose()).norm(), 1e-7 * analytic.norm()) << c.label;
  }
}

TEST_P(MembraneElementTest, TheGradientAloneEqualsTheGradientComputedWithTheHessian) {
  // membrane_gradient carries no Hessian through its jet (residuals and line searches call it most); its
  // gradient comes from the same expressions, so it agrees to rounding, plain and relaxed.
  const Case c = GetParam();
  const std::vector<Trial> all = trials(c, 19);
  for (size_t trial = 0; trial < all.size(); ++trial) {
    const auto& [rest, x, r] = all[trial];
    for (const bool tension_field : {false, true}) {
      double energy;
      Vector9d with_hessian;
      Matrix9d hessian;
      membrane_energy_gradient_hessian(c.material, 0.5, r, x, energy, with_hessian, hessian, false, tension_field);
      const Vector9d alone = membrane_gradient(c.material, 0.5, r, x, tension_field);
      EXPECT_LE((alone - with_hessian).norm(), 1e-14 * with_hessian.norm()) << c.label << " trial " << trial;
    }
  }
}

TEST_P(MembraneElementTest, MixedRestDerivativeMatchesFiniteDifferences) {
  const Case c = GetParam();
  const std::vector<Trial> all = trials(c, 13);
  for (size_t trial = 0; trial < all.size(); ++trial) {
    const auto& [rest, x, r] = all[trial];
    const Matrix9d analytic = membrane_mixed_derivative(c.material, 0.5, rest, x);
    const double step = 1e-6 * rest.norm() * (c.sliver ? 1e-2 : 1.0);
    const Matrix9d numeric = test::central_difference_jacobian(
        [&](const Vector9d& y) { return membrane_gradient(c.material, 0.5, make_rest_triangle(y), x); }, rest, step);
    ASSERT_GT(analytic.norm(), 1e-10) << c.label;
    EXPECT_LT(relative_error(analytic, numeric), 1e-5) << c.label << " trial " << trial;
  }
}

TEST_P(MembraneElementTest, ProjectedHessianIsPositiveSemiDefinite) {
  const Case c = GetParam();
  std::mt19937 rng(17);
  const Vector9d rest = rest_triangle(rng, c.sliver);
  const Vector9d x = deformed_triangle(rng, rest, c.stretch);
  double energy;
  Vector9d gradient;
  Matrix9d projected;
  membrane_energy_gradient_hessian(c.material, 0.5, make_rest_triangle(rest), x, energy, gradient, projected, true);
  const double smallest = Eigen::SelfAdjointEigenSolver<Matrix9d>(projected).eigenvalues().minCoeff();
  EXPECT_GE(smallest, -1e-10 * projected.norm()) << c.label;
}

INSTANTIATE_TEST_SUITE_P(AllMaterials, MembraneElementTest, ::testing::ValuesIn(cases()),
                         [](const auto& test_info) {
                           std::string name = test_info.param.label;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

TEST(MembraneElement, RestStateHasZeroEnergyAndForce) {
  Vector9d rest;
  rest << 0, 0, 0, 3, 0, 0, 1, 2, 0.5;
  for (const auto& c : cases()) {
    const RestTriangle r = make_rest_triangle(rest);
    EXPECT_NEAR(membrane_energy(c.material, 0.5, r, rest), 0.0, 1e-12) << c.label;
    EXPECT_LT(membrane_gradient(c.material, 0.5, r, rest).norm(), 1e-12) << c.label;
  }
}

TEST(MembraneElement, EquibiaxialEnergyMatchesClosedForm) {
  // A triangle stretched by l in its plane: I1 = 2 l^2 + l^-4, Psi_NH = mu/2 (I1 - 3), W = h A Psi.
  Vector9d rest;
  rest << 0, 0, 0, 2, 0, 0, 0.5, 1.7, 0;
  const RestTriangle r = make_rest_triangle(rest);
  const double l = 2.2, mu = 0.3, h = 0.5;
  const double expected = h * r.area * 0.5 * mu * (2 * l * l + std::pow(l, -4) - 3);
  EXPECT_NEAR(membrane_energy(make(MaterialModel::NeoHookean, mu), h, r, l * rest), expected, 1e-12 * expected);
  const Eigen::Vector2d stretches = principal_stretches_squared(r, l * rest);
  // The repeated eigenvalue comes through a square root of a round-off-sized discriminant.
  EXPECT_NEAR(stretches[0], l * l, 1e-6);
  EXPECT_NEAR(stretches[1], l * l, 1e-6);
}


// Tension field (Pipkin's relaxed energy): taut, wrinkled and slack triangles, against finite
// differences of the relaxed energy and gradient, for every law.
struct TensionCase {
  const char* label;
  Material material;
  double l1, l2;  // in-plane principal stretches applied to the rest triangle
};

std::vector<TensionCase> tension_cases() {
  const Material silicone = make(MaterialModel::HartSmith, 0.131735, 0.0260802, 0.971018);
  const Material latex = make(MaterialModel::HartSmith, 0.181396, 0.00029924, 0.490755);
  return {
      {"taut-neo-hookean", make(MaterialModel::NeoHookean, 0.3), 1.5, 1.2},
      {"wrinkled-neo-hookean", make(MaterialModel::NeoHookean, 0.3), 1.6, 0.6},
      {"wrinkled-mooney-rivlin", make(MaterialModel::MooneyRivlin, 0.18, 0.02), 1.6, 0.5},
      {"wrinkled-silicone", silicone, 2.0, 0.5},
      {"wrinkled-latex-large", latex, 4.0, 0.4},
      {"wrinkled-near-rest", silicone, 1.05, 0.9},
  };
}

/// Rest triangle in a tilted plane, and a deformed copy stretched by l1, l2 along in-plane axes at
/// 30 degrees to the first edge, rotated in space, with a perturbation far below the state boundaries.
void tension_pair(std::mt19937& rng, double l1, double l2, Vector9d& rest, Vector9d& x, double noise = 1e-3) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix<double, 2, 3> planar;
  planar << 0, 2.0 + 0.2 * u(rng), 0.7 + 0.2 * u(rng), 0, 0.1 * u(rng), 1.6 + 0.2 * u(rng);
  const double angle = 0.5236;
  Eigen::Matrix2d axes;
  axes << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  const Eigen::Matrix2d stretch = axes * Eigen::Vector2d(l1, l2).asDiagonal() * axes.transpose();
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.9, Eigen::Vector3d(0, 1, 2).normalized()).toRotationMatrix();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d p = planar.col(k);
    const Eigen::Vector2d q = stretch * p;
    rest.segment<3>(3 * k) = tilt * Eigen::Vector3d(p[0], p[1], 0.0);
    x.segment<3>(3 * k) = turn * Eigen::Vector3d(q[0], q[1], 0.0) + noise * Eigen::Vector3d(u(rng), u(rng), u(rng));
  }
}

class TensionFieldTest : public ::testing::TestWithParam<TensionCase> {};

TEST_P(TensionFieldTest, GradientMatchesFiniteDifferencesOfRelaxedEnergy) {
  const TensionCase c = GetParam();
  std::mt19937 rng(23);
  for (int trial = 0; trial < 5; ++trial) {
    Vector9d rest, x;
    tension_pair(rng, c.l1, c.l2, rest, x);
    const RestTriangle r = make_rest_triangle(rest);
    EXPECT_EQ(is_relaxed(r, x), c.l1 * c.l2 * c.l2 < 1.0) << c.label;
    const Vector9d analytic = membrane_gradient(c.material, 0.5, r, x, true);
    const Vector9d numeric = test::central_difference_gradient(
        [&](const Vector9d& y) { return membrane_energy(c.material, 0.5, r, y, true); }, x, 1e-6 * x.norm());
    ASSERT_GT(analytic.norm(), 1e-6) << c.label;
    EXPECT_LT(relative_error(analytic, numeric), 1e-6) << c.label << " trial " << trial;
  }
}

TEST_P(TensionFieldTest, HessianMatchesFiniteDifferencesOfGradientAndIsPositiveSemiDefinite) {
  const TensionCase c = GetParam();
  std::mt19937 rng(29);
  for (int trial = 0; trial < 5; ++trial) {
    Vector9d rest, x;
    tension_pair(rng, c.l1, c.l2, rest, x);
    const RestTriangle r = make_rest_triangle(rest);
    double energy;
    Vector9d gradient;
    Matrix9d analytic;
    membrane_energy_gradient_hessian(c.material, 0.5, r, x, energy, gradient, analytic, false, true);
    EXPECT_NEAR(energy, membrane_energy(c.material, 0.5, r, x, true), 1e-12 * std::abs(energy)) << c.label;
    const Matrix9d numeric = test::central_difference_jacobian(
        [&](const Vector9d& y) { return membrane_gradient(c.material, 0.5, r, y, true); }, x, 1e-6 * x.norm());
    ASSERT_GT(analytic.norm(), 1e-6) << c.label;
    EXPECT_LT(relative_error(analytic, numeric), 1e-5) << c.label << " trial " << trial;
    if (is_relaxed(r, x)) {
      const double smallest = Eigen::SelfAdjointEigenSolver<Matrix9d>(analytic).eigenvalues().minCoeff();
      EXPECT_GE(smallest, -1e-10 * analytic.norm()) << c.label;
    }
  }
}

TEST_P(TensionFieldTest, MixedRestDerivativeMatchesFiniteDifferences) {
  const TensionCase c = GetParam();
  std::mt19937 rng(31);
  Vector9d rest, x;
  tension_pair(rng, c.l1, c.l2, rest, x);
  const Matrix9d analytic = membrane_mixed_derivative(c.material, 0.5, rest, x, true);
  const Matrix9d numeric = test::central_difference_jacobian(
      [&](const Vector9d& y) { return membrane_gradient(c.material, 0.5, make_rest_triangle(y), x, true); }, rest,
      1e-6 * rest.norm());
  ASSERT_GT(analytic.norm(), 1e-6) << c.label;
  EXPECT_LT(relative_error(analytic, numeric), 1e-5) << c.label;
}

INSTANTIATE_TEST_SUITE_P(States, TensionFieldTest, ::testing::ValuesIn(tension_cases()), [](const auto& test_info) {
  std::string name = test_info.param.label;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return name;
});

TEST(TensionField, SlackTriangleHasNoEnergyNoForceNoStiffness) {
  std::mt19937 rng(37);
  Vector9d rest, x;
  tension_pair(rng, 0.8, 0.7, rest, x);
  const RestTriangle r = make_rest_triangle(rest);
  const Material nh = make(MaterialModel::NeoHookean, 0.3);
  EXPECT_TRUE(is_relaxed(r, x));
  EXPECT_GT(membrane_energy(nh, 0.5, r, x, false), 1e-3);  // the unrelaxed law would store energy
  EXPECT_EQ(membrane_energy(nh, 0.5, r, x, true), 0.0);
  EXPECT_EQ(membrane_gradient(nh, 0.5, r, x, true).norm(), 0.0);
  double energy;
  Vector9d gradient;
  Matrix9d hessian;
  membrane_energy_gradient_hessian(nh, 0.5, r, x, energy, gradient, hessian, false, true);
  EXPECT_EQ(hessian.norm(), 0.0);
}

TEST(TensionField, EnergyIsContinuousAcrossTheWrinklingBoundary) {
  // At l2 = l1^-1/2 the lateral stress vanishes: the relaxed and unrelaxed energies and forces agree on
  // both sides to first order.
  const Material silicone = make(MaterialModel::HartSmith, 0.131735, 0.0260802, 0.971018);
  for (double l1 : {1.2, 2.0, 3.5}) {
    const double natural = 1.0 / std::sqrt(l1);
    for (double offset : {-1e-6, 1e-6}) {
      std::mt19937 rng(41);
      Vector9d rest, x;
      tension_pair(rng, l1, natural * (1.0 + offset), rest, x, 0.0);
      const RestTriangle r = make_rest_triangle(rest);
      const double relaxed = membrane_energy(silicone, 0.5, r, x, true);
      const double plain = membrane_energy(silicone, 0.5, r, x, false);
      EXPECT_NEAR(relaxed, plain, 1e-6 * plain) << "l1 " << l1 << " offset " << offset;
      const Vector9d g_relaxed = membrane_gradient(silicone, 0.5, r, x, true);
      const Vector9d g_plain = membrane_gradient(silicone, 0.5, r, x, false);
      EXPECT_LT((g_relaxed - g_plain).norm(), 1e-4 * g_plain.norm()) << "l1 " << l1 << " offset " << offset;
    }
  }
}

}  // namespace
}  // namespace balloon::fem
