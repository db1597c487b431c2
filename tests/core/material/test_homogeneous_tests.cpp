#include "material/homogeneous_tests.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace balloon {
namespace {

Material make(MaterialModel model, double a, double b = 0.0, double c = 0.0) {
  Material m;
  m.model = model;
  m.params = {a, b, c};
  return m;
}

std::vector<Material> test_materials() {
  return {make(MaterialModel::NeoHookean, 0.3), make(MaterialModel::MooneyRivlin, 0.2, 0.05),
          make(MaterialModel::HartSmith, 0.15, 3e-3, 0.8),
          make(MaterialModel::HartSmith, 0.15, 1e-2, 0.8)};  // stiff: exp(k1 (I1-3)^2) ~ 4e3 in ET at l = 4
}

const Deformation ALL_DEFORMATIONS[] = {Deformation::Uniaxial, Deformation::Equibiaxial, Deformation::PureShear};

/// Central difference of W(l); the equibiaxial stress is half of it (two loaded directions).
double fd_stress(const Material& m, Deformation d, double l) {
  const double h = 1e-5 * l;
  const double dW = (strain_energy_density(m, d, l + h) - strain_energy_density(m, d, l - h)) / (2.0 * h);
  return d == Deformation::Equibiaxial ? 0.5 * dW : dW;
}

TEST(HomogeneousTests, InvariantsMatchPrincipalStretches) {
  const double l = 1.7;
  const double stretches[3][3] = {{l, 1 / std::sqrt(l), 1 / std::sqrt(l)}, {l, l, 1 / (l * l)}, {l, 1.0, 1 / l}};
  for (int k = 0; k < 3; ++k) {
    const auto* s = stretches[k];
    const double I1 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
    const double I2 = 1 / (s[0] * s[0]) + 1 / (s[1] * s[1]) + 1 / (s[2] * s[2]);
    const auto inv = deformation_invariants(ALL_DEFORMATIONS[k], l);
    EXPECT_NEAR(inv.I1, I1, 1e-12);
    EXPECT_NEAR(inv.I2, I2, 1e-12);
  }
}

TEST(HomogeneousTests, NominalStressMatchesFiniteDifferenceOfEnergy) {
  for (const auto& m : test_materials()) {
    for (auto d : ALL_DEFORMATIONS) {
      for (double l : {1.05, 1.3, 2.0, 3.0, 4.0}) {
        const double analytic = nominal_stress(m, d, l);
        const double numeric = fd_stress(m, d, l);
        ASSERT_GT(std::abs(numeric), 1e-6) << "zero stress would make the comparison vacuous";
        EXPECT_NEAR(analytic / numeric, 1.0, 1e-6)
            << "model " << model_name(m.model) << " k1=" << m.params[1] << " deformation " << static_cast<int>(d) << " l=" << l;
      }
    }
  }
}

TEST(HomogeneousTests, StiffHartSmithAtStretchFourMatchesFiniteDifference) {
  const auto m = make(MaterialModel::HartSmith, 0.15, 1e-2, 0.8);
  for (auto d : ALL_DEFORMATIONS) {
    const double analytic = nominal_stress(m, d, 4.0);
    const double numeric = fd_stress(m, d, 4.0);
    ASSERT_GT(numeric, 1.0);  // well into the exponential branch
    EXPECT_NEAR(analytic / numeric, 1.0, 1e-6);
  }
}

TEST(HomogeneousTests, StressIsZeroAtRestAndSmallStrainSlopeIsYoungsModulus) {
  for (const auto& m : test_materials()) {
    for (auto d : ALL_DEFORMATIONS) EXPECT_NEAR(nominal_stress(m, d, 1.0), 0.0, 1e-15);
    // Linear elasticity of an incompressible solid: E = 3 mu in uniaxial, 6 mu in equibiaxial, 4 mu in
    // pure shear (nominal stress per unit strain).
    const double h = 1e-6, mu = m.shear_modulus();
    ASSERT_GT(mu, 0.0);
    EXPECT_NEAR(nominal_stress(m, Deformation::Uniaxial, 1 + h) / h, 3 * mu, 1e-4 * mu);
    EXPECT_NEAR(nominal_stress(m, Deformation::Equibiaxial, 1 + h) / h, 6 * mu, 1e-4 * mu);
    EXPECT_NEAR(nominal_stress(m, Deformation::PureShear, 1 + h) / h, 4 * mu, 1e-4 * mu);
  }
}

TEST(HomogeneousTests, SpherePressureMatchesVirtualWork) {
  // p dV = (rest wall volume) dW:  p 4 pi R^3 l^2 dl = 4 pi R^2 H dW_ET  =>  p = H W_ET'(l) / (R l^2).
  const double R = 10.0, H = 0.3;
  for (const auto& m : test_materials()) {
    for (double l : {1.1, 1.5, 2.5, 4.0}) {
      const double h = 1e-5 * l;
      const double dW = (strain_energy_density(m, Deformation::Equibiaxial, l + h) -
                         strain_energy_density(m, Deformation::Equibiaxial, l - h)) / (2 * h);
      const double expected = H * dW / (R * l * l);
      ASSERT_GT(expected, 1e-6);
      EXPECT_NEAR(sphere_pressure(m, R, H, l) / expected, 1.0, 1e-6);
    }
  }
}

TEST(HomogeneousTests, NeoHookeanSphereHasItsKnownPressureMaximum) {
  // p ~ l^-1 - l^-7 peaks at l = 7^(1/6) = 1.3831 (the classic balloon instability).
  const auto m = make(MaterialModel::NeoHookean, 0.3);
  const double peak = std::pow(7.0, 1.0 / 6.0);
  EXPECT_GT(sphere_pressure(m, 10, 0.3, peak), sphere_pressure(m, 10, 0.3, peak - 0.01));
  EXPECT_GT(sphere_pressure(m, 10, 0.3, peak), sphere_pressure(m, 10, 0.3, peak + 0.01));
  EXPECT_NEAR(sphere_pressure(m, 10, 0.3, peak), 2 * 0.3 / 10 * 0.3 * (1 / peak - std::pow(peak, -7.0)), 1e-12);
}

}  // namespace
}  // namespace balloon
