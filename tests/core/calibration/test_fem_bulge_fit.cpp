#include "calibration/fem_bulge_fit.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <iostream>

#include "axisymmetric_membrane.hpp"

namespace balloon {
namespace {

Material hart_smith(double G, double k1, double k2) {
  Material m;
  m.model = MaterialModel::HartSmith;
  m.params = {G, k1, k2};
  return m;
}

constexpr double RADIUS = 10.0;    // mm
constexpr double THICKNESS = 0.5;  // mm

}  // namespace
}  // namespace balloon

namespace balloon {
namespace {

/// Bulge data from the independent axisymmetric solution: one shot per pole stretch gives (rho, p).
MeasurementSet shooting_bulge_data(const Material& material, const std::vector<double>& pole_stretches) {
  MeasurementSet set;
  set.kind = TestKind::Bulge;
  set.disc_radius_mm = RADIUS;
  set.thickness_mm = THICKNESS;
  set.label = "shooting";
  for (double stretch : pole_stretches) {
    const testing::AxisymmetricBulge b = testing::shoot_axisymmetric_bulge(material, RADIUS, THICKNESS, stretch);
    EXPECT_TRUE(b.ok);
    set.x.push_back(b.extension_ratio);
    set.y.push_back(b.pressure_kpa);
  }
  return set;
}

TEST(FemBulgeFit, FemCorrectedFitRecoversHartSmithFromTheAxisymmetricSolution) {
  const Material truth = hart_smith(0.2, 3e-3, 0.5);
  const MeasurementSet set =
      shooting_bulge_data(truth, {1.03, 1.08, 1.15, 1.25, 1.4, 1.6, 1.8, 2.0, 2.3, 2.6});
  ASSERT_EQ(set.x.size(), 10u);
  ASSERT_TRUE(measurement_problem(set).empty()) << measurement_problem(set);
  const auto start = std::chrono::steady_clock::now();
  const Result<FitResult> fit = fit_material_with_fem_bulge(MaterialModel::HartSmith, {set}, FitOptions{}, 12);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(fit) << fit.error();
  std::cout << "FEM-corrected bulge fit: " << material_spec(fit->material) << ", rms " << fit->rms_residual
            << " kPa, relative rms " << fit->rms_relative_residual << ", " << seconds << " s; " << fit->message << "\n";
  EXPECT_NE(fit->message.find("FEM bulge correction converged"), std::string::npos) << fit->message;
  // 12 rings carry about 1% mesh error; the data are reproduced to about 0.4% (rms). Bulge data alone pin
  // the small-strain modulus 2 G (1 + k2 / 3) (measured 0.3% off) but leave a flat valley between G and k2
  // (measured: G 6% high, k2 0.30 instead of 0.5), so k1 and k2 are checked against the fit's own standard
  // errors rather than a fixed percentage.
  ASSERT_EQ(fit->std_errors.size(), 3u);
  std::cout << "standard errors: G " << fit->std_errors[0] << " k1 " << fit->std_errors[1] << " k2 " << fit->std_errors[2] << "\n";
  EXPECT_LT(fit->rms_relative_residual, 0.01);
  EXPECT_NEAR(fit->material.shear_modulus(), truth.shear_modulus(), 0.02 * truth.shear_modulus());
  EXPECT_NEAR(fit->material.params[0], 0.2, 0.1 * 0.2);
  EXPECT_NEAR(fit->material.params[1], 3e-3, 3 * fit->std_errors[1]);
  EXPECT_NEAR(fit->material.params[2], 0.5, 3 * fit->std_errors[2]);
  EXPECT_LT(fit->std_errors[2], 0.5) << "k2 should still be identified to within its own size";
}

}  // namespace
}  // namespace balloon
