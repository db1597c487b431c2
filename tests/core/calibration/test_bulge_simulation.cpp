#include "calibration/bulge_simulation.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

#include "axisymmetric_membrane.hpp"

namespace balloon {
namespace {

Material neo_hookean(double mu) {
  Material m;
  m.model = MaterialModel::NeoHookean;
  m.params = {mu, 0, 0};
  return m;
}

Material hart_smith(double G, double k1, double k2) {
  Material m;
  m.model = MaterialModel::HartSmith;
  m.params = {G, k1, k2};
  return m;
}

constexpr double RADIUS = 10.0;    // mm
constexpr double THICKNESS = 0.5;  // mm
constexpr int RINGS = 16;          // 817 vertices

BulgeTestOptions options_for(const Material& material) {
  BulgeTestOptions options;
  options.material = material;
  options.radius_mm = RADIUS;
  options.thickness_mm = THICKNESS;
  options.rings = RINGS;
  return options;
}

TEST(BulgeTest, DiscMeshIsRegularWithTheRimOnTheCircle) {
  const int rings = 8;
  const TriMesh disc = bulge_disc_mesh(RADIUS, rings);
  ASSERT_EQ(disc.vertex_count(), 1 + 3 * rings * (rings + 1));
  ASSERT_EQ(disc.face_count(), 6 * rings * rings);
  for (int v : bulge_disc_rim(rings)) EXPECT_NEAR(disc.vertices.row(v).norm(), RADIUS, 1e-12);
  double area = 0, smallest_angle = 180;
  for (int f = 0; f < disc.face_count(); ++f) {
    const Eigen::Vector3d a = disc.vertices.row(disc.faces(f, 0)), b = disc.vertices.row(disc.faces(f, 1)),
                          c = disc.vertices.row(disc.faces(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    EXPECT_GT(n.z(), 0.0) << "triangle " << f << " is not counter-clockwise seen from +z";
    area += 0.5 * n.norm();
    const Eigen::Vector3d p[3] = {a, b, c};
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d u = p[(i + 1) % 3] - p[i], w = p[(i + 2) % 3] - p[i];
      smallest_angle = std::min(smallest_angle, std::acos(u.normalized().dot(w.normalized())) * 180 / M_PI);
    }
  }
  // The inscribed 48-gon covers the circle up to 1 - sin(2 pi/48) 48 / (2 pi) = 0.29%.
  EXPECT_NEAR(area / (M_PI * RADIUS * RADIUS), 1.0, 0.004);
  EXPECT_GT(smallest_angle, 29.99);  // equilateral-like: no sliver
}

/// FEM pressure at the FEM apex height against the shooting solution at that same apex height.
void expect_pressure_matches_shooting(const Material& material, double pressure_kpa) {
  const auto start = std::chrono::steady_clock::now();
  const BulgeState fem = inflate_bulge_to_pressure(options_for(material), pressure_kpa);
  const double fem_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(fem.converged) << fem.message;
  EXPECT_NEAR(fem.pressure_kpa, pressure_kpa, 1e-9 * pressure_kpa);
  const testing::AxisymmetricBulge exact =
      testing::axisymmetric_bulge_at_apex_height(material, RADIUS, THICKNESS, fem.apex_height_mm);
  ASSERT_TRUE(exact.ok);
  EXPECT_NEAR(exact.apex_height_mm, fem.apex_height_mm, 1e-6 * fem.apex_height_mm);
  const double pressure_error = std::abs(exact.pressure_kpa - fem.pressure_kpa) / exact.pressure_kpa;
  const double ratio_error = std::abs(exact.extension_ratio - fem.extension_ratio) / (exact.extension_ratio - 1.0);
  std::cout << model_name(material.model) << " p=" << pressure_kpa << " kPa: apex " << fem.apex_height_mm
            << " mm, rho fem " << fem.extension_ratio << " shooting " << exact.extension_ratio
            << ", shooting p " << exact.pressure_kpa << " kPa, pressure error " << 100 * pressure_error
            << "%, (rho-1) error " << 100 * ratio_error << "%, FEM " << fem_s << " s\n";
  EXPECT_LT(pressure_error, 0.01);
  EXPECT_LT(ratio_error, 0.02);
}

TEST(BulgeTest, NeoHookeanMatchesAxisymmetricShootingWithinOnePercent) {
  const Material material = neo_hookean(0.4);
  // The Neo-Hookean disc peaks at about 2 mu H / a * 0.95 ~ 38 kPa here; stay below the maximum.
  expect_pressure_matches_shooting(material, 10.0);
  expect_pressure_matches_shooting(material, 25.0);
}

TEST(BulgeTest, HartSmithMatchesAxisymmetricShootingWithinOnePercent) {
  const Material material = hart_smith(0.2, 3e-3, 0.5);
  expect_pressure_matches_shooting(material, 10.0);
  expect_pressure_matches_shooting(material, 30.0);
}

TEST(BulgeTest, VolumeControlPassesThePressureMaximum) {
  const Material material = neo_hookean(0.4);
  std::vector<double> volumes;
  for (double rho : {1.05, 1.2, 1.4, 1.6, 1.8, 2.0}) volumes.push_back(bulge_cap_volume(RADIUS, rho));
  const BulgeCurve curve = bulge_volume_sweep(options_for(material), volumes, true);
  ASSERT_TRUE(curve.converged) << curve.message;
  ASSERT_EQ(curve.points.size(), volumes.size());
  size_t peak = 0;
  for (size_t i = 0; i < curve.points.size(); ++i) {
    if (curve.points[i].pressure_kpa > curve.points[peak].pressure_kpa) peak = i;
    if (i > 0) {
      EXPECT_GT(curve.points[i].extension_ratio, curve.points[i - 1].extension_ratio);
    }
  }
  EXPECT_GT(peak, 0u);
  EXPECT_LT(peak, curve.points.size() - 1) << "the sweep should pass the maximum";
  // Past the maximum: the last state against shooting at the same apex height.
  const BulgeState& last = curve.points.back();
  const testing::AxisymmetricBulge exact =
      testing::axisymmetric_bulge_at_apex_height(material, RADIUS, THICKNESS, last.apex_height_mm);
  ASSERT_TRUE(exact.ok);
  const double error = std::abs(exact.pressure_kpa - last.pressure_kpa) / exact.pressure_kpa;
  std::cout << "past the maximum: rho " << last.extension_ratio << " apex " << last.apex_height_mm << " mm, p fem "
            << last.pressure_kpa << " shooting " << exact.pressure_kpa << " kPa, error " << 100 * error << "%, "
            << curve.time_s << " s\n";
  EXPECT_LT(error, 0.01);
  // Pressure control above the maximum has no equilibrium and says so.
  const BulgeState above = inflate_bulge_to_pressure(options_for(material), 2 * curve.points[peak].pressure_kpa);
  EXPECT_FALSE(above.converged);
  EXPECT_NE(above.message.find("maximum"), std::string::npos) << above.message;
}

TEST(BulgeTest, FemBulgeModelInterpolatesTheVolumeSweep) {
  const Material material = neo_hookean(0.4);
  MeasurementSet set;
  set.kind = TestKind::Bulge;
  set.disc_radius_mm = RADIUS;
  set.thickness_mm = THICKNESS;
  set.x = {1.0, 1.1, 1.3};
  set.y = {0, 1, 2};
  const std::vector<double> p = fem_bulge_pressures(material, set, 8);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0], 0.0);
  for (int i = 1; i < 3; ++i) {
    const testing::AxisymmetricBulge exact =
        testing::axisymmetric_bulge_at_extension_ratio(material, RADIUS, THICKNESS, set.x[static_cast<size_t>(i)]);
    ASSERT_TRUE(exact.ok);
    // Coarse mesh (8 rings) and linear interpolation: a few percent.
    EXPECT_NEAR(p[static_cast<size_t>(i)], exact.pressure_kpa, 0.05 * exact.pressure_kpa);
  }
}

}  // namespace
}  // namespace balloon
