// The pressure-volume curve against the thin sphere's closed form p = h Psi'(l) / (R l^2): every point of
// one continuation path, the Neo-Hookean pressure maximum at l = 7^(1/6), and hostile ranges.
#include <gtest/gtest.h>

#include <cmath>

#include "material/homogeneous_tests.hpp"
#include "material/material.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "mesh/self_intersection.hpp"
#include "core/mesh/mesh_test_helpers.hpp"
#include "solve/pressure_volume_curve.hpp"

namespace balloon {
namespace {

Material make(MaterialModel model, double a, double b = 0, double c = 0) {
  Material m;
  m.model = model;
  m.params = {a, b, c};
  return m;
}

/// The polyhedron's own radius: the sphere with its volume-to-area ratio.
double effective_radius(const TriMesh& sphere) {
  return 3.0 * enclosed_volume(sphere.vertices, sphere.faces) / surface_area(sphere.vertices, sphere.faces);
}

PressureVolumeCurveOptions volume_curve(const Material& material, double from, double to, int points) {
  PressureVolumeCurveOptions options;
  options.material = material;
  options.thickness_mm = 0.5;
  options.control = InflationControl::VolumeRatio;
  options.from = from;
  options.to = to;
  options.points = points;
  return options;
}

TEST(PressureVolumeCurve, TargetsAreGeometric) {
  const std::vector<double> targets = curve_targets(1.01, 250.0, 5);
  ASSERT_EQ(targets.size(), 5u);
  EXPECT_DOUBLE_EQ(targets.front(), 1.01);
  EXPECT_DOUBLE_EQ(targets.back(), 250.0);
  const double ratio = std::pow(250.0 / 1.01, 0.25);
  for (size_t i = 1; i < targets.size(); ++i) EXPECT_NEAR(targets[i] / targets[i - 1], ratio, 1e-12 * ratio);
}

struct CurveCase {
  const char* label;
  Material material;
  double to;
};

class CurveSphereLawTest : public ::testing::TestWithParam<CurveCase> {};

// Along the whole path, past the pressure maximum, every point within 0.5% of the closed form.
TEST_P(CurveSphereLawTest, EveryPointMatchesTheClosedFormWithinHalfPercent) {
  const CurveCase c = GetParam();
  const TriMesh sphere = make_icosphere(10.0, 3);  // 642 vertices
  const double radius = effective_radius(sphere);
  const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, volume_curve(c.material, 1.05, c.to, 12));
  ASSERT_TRUE(curve.converged) << c.label << ": " << curve.message;
  ASSERT_EQ(curve.points.size(), 12u);
  for (const CurvePoint& point : curve.points) {
    ASSERT_TRUE(point.converged) << point.message;
    ASSERT_TRUE(point.volume_ratio && point.pressure_kpa && point.mean_stretch && point.max_stretch);
    EXPECT_NEAR(*point.volume_ratio, point.target, 1e-6 * point.target);
    const double stretch = std::cbrt(*point.volume_ratio);
    const double expected = 1e3 * sphere_pressure(c.material, radius, 0.5, stretch);
    EXPECT_NEAR(*point.pressure_kpa, expected, 5e-3 * std::abs(expected)) << c.label << " at stretch " << stretch;
    EXPECT_NEAR(*point.mean_stretch, stretch, 2e-3 * stretch);
    EXPECT_GE(*point.max_stretch, *point.mean_stretch * (1 - 1e-9));
    EXPECT_TRUE(point.unstable_modes.has_value());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Laws, CurveSphereLawTest,
    ::testing::Values(CurveCase{"neo_hookean", make(MaterialModel::NeoHookean, 0.3), 27.0},
                      CurveCase{"hart_smith", make(MaterialModel::HartSmith, 0.1, 3e-4, 1.0), 125.0}),
    [](const auto& test_info) { return std::string(test_info.param.label); });

// The Neo-Hookean sphere's only pressure extremum is the maximum at l = 7^(1/6) = 1.383 (V/V0 = sqrt 7):
// 16 points over 1.01..8 are 3.8% apart in stretch; the parabola puts the maximum within 1% of it.
TEST(PressureVolumeCurve, FindsTheNeoHookeanPressureMaximum) {
  const TriMesh sphere = make_icosphere(10.0, 2);  // 162 vertices
  const Material nh = make(MaterialModel::NeoHookean, 0.3);
  const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, volume_curve(nh, 1.01, 8.0, 16));
  ASSERT_TRUE(curve.converged) << curve.message;
  ASSERT_EQ(curve.extrema.size(), 1u);
  const CurveExtremum& peak = curve.extrema.front();
  EXPECT_TRUE(peak.maximum);
  const double expected_stretch = std::pow(7.0, 1.0 / 6.0);
  EXPECT_NEAR(std::cbrt(peak.volume_ratio), expected_stretch, 1e-2 * expected_stretch);
  const double expected_pressure = 1e3 * sphere_pressure(nh, effective_radius(sphere), 0.5, expected_stretch);
  EXPECT_NEAR(peak.pressure_kpa, expected_pressure, 1e-2 * expected_pressure);
  // The sampled point is the largest pressure of the curve, and both sides fall away from it.
  for (const CurvePoint& point : curve.points) EXPECT_LE(*point.pressure_kpa, *curve.points[peak.point].pressure_kpa);
}

// Pressure control climbs the ascending branch, where the stiffness is positive definite, and ends with
// a stated reason at the first pressure above the maximum; the points after it have no values.
TEST(PressureVolumeCurve, PressureControlStopsAtThePressureMaximum) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  const Material nh = make(MaterialModel::NeoHookean, 0.3);
  const double radius = effective_radius(sphere);
  const double peak = 1e3 * sphere_pressure(nh, radius, 0.5, std::pow(7.0, 1.0 / 6.0));
  PressureVolumeCurveOptions options = volume_curve(nh, 0.2 * peak, 2.0 * peak, 8);
  options.control = InflationControl::Pressure;
  const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, options);
  EXPECT_FALSE(curve.converged);
  EXPECT_EQ(curve.stop, InflationStop::AboveMaximumPressure) << curve.message;
  ASSERT_EQ(curve.points.size(), 8u);
  int converged = 0;
  for (const CurvePoint& point : curve.points) {
    if (point.converged) {
      ++converged;
      EXPECT_NEAR(*point.pressure_kpa, point.target, 1e-9 * point.target);
      const double expected = 1e3 * sphere_pressure(nh, radius, 0.5, std::cbrt(*point.volume_ratio));
      EXPECT_NEAR(*point.pressure_kpa, expected, 5e-3 * expected);
      EXPECT_EQ(point.unstable_modes, 0);
    } else {
      EXPECT_GT(point.target, 0.99 * peak);
      EXPECT_FALSE(point.pressure_kpa || point.volume_ratio || point.mean_stretch || point.max_stretch ||
                   point.unstable_modes);
      EXPECT_FALSE(point.message.empty());
    }
  }
  // 0.2 peak * 10^(k/7) stays below the peak for k <= 4.
  EXPECT_EQ(converged, 5);
  EXPECT_NE(curve.message.find("maximum pressure"), std::string::npos) << curve.message;
}

// A stiffening rubber's pressure climbs again after its maximum (Hart-Smith, issue 14's parameters), so
// under pressure control a pressure above the maximum is the larger shape the balloon snaps to. The
// maximum and the minimum that the path passed between two points are named, at the closed form's.
TEST(PressureVolumeCurve, PressureControlNamesTheMaximumItSnapsPast) {
  const TriMesh sphere = make_icosphere(10.0, 2);  // 162 vertices
  const Material rubber = make(MaterialModel::HartSmith, 0.12, 5e-4, 0.8);
  const double radius = effective_radius(sphere);
  double max_kpa = 0.0, max_stretch = 1.0, min_kpa = 0.0, min_stretch = 1.0;
  for (double stretch = 1.0; stretch < 8.0; stretch += 1e-4) {
    const double p = 1e3 * sphere_pressure(rubber, radius, 0.5, stretch);
    if (min_kpa == 0.0 && p > max_kpa) max_kpa = p, max_stretch = stretch;
    if (p < max_kpa && (min_kpa == 0.0 || p < min_kpa)) min_kpa = p, min_stretch = stretch;
  }
  ASSERT_GT(max_stretch, 1.1);
  ASSERT_GT(min_stretch, max_stretch);
  // 0.5, 0.6, 0.73, 0.88, 1.07 and 1.3 times the maximum: the last two past it.
  PressureVolumeCurveOptions options = volume_curve(rubber, 0.5 * max_kpa, 1.3 * max_kpa, 6);
  options.control = InflationControl::Pressure;
  const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, options);
  ASSERT_TRUE(curve.converged) << curve.message;
  for (const CurvePoint& point : curve.points) {
    const double expected = 1e3 * sphere_pressure(rubber, radius, 0.5, std::cbrt(*point.volume_ratio));
    EXPECT_NEAR(*point.pressure_kpa, expected, 5e-3 * expected) << "at " << point.target << " kPa";
  }
  EXPECT_LT(*curve.points[3].volume_ratio, std::pow(max_stretch, 3));
  EXPECT_GT(*curve.points[4].volume_ratio, std::pow(min_stretch, 3));  // on the far branch
  ASSERT_EQ(curve.extrema.size(), 2u);
  const CurveExtremum& peak = curve.extrema[0];
  const CurveExtremum& valley = curve.extrema[1];
  EXPECT_TRUE(peak.maximum);
  EXPECT_FALSE(valley.maximum);
  EXPECT_EQ(peak.point, 4);
  EXPECT_EQ(valley.point, 4);
  // Measured: 0.7% and 0.8% from the closed form in pressure, 0.9% and 1.4% in stretch (162 vertices, the
  // parabola through the volume path's steps).
  EXPECT_NEAR(peak.pressure_kpa, max_kpa, 1.5e-2 * max_kpa);
  EXPECT_NEAR(valley.pressure_kpa, min_kpa, 1.5e-2 * min_kpa);
  EXPECT_NEAR(std::cbrt(peak.volume_ratio), max_stretch, 3e-2 * max_stretch);
  EXPECT_NEAR(std::cbrt(valley.volume_ratio), min_stretch, 3e-2 * min_stretch);
}

TEST(PressureVolumeCurve, BadRangesAreReportedNotThrown) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  const Material nh = make(MaterialModel::NeoHookean, 0.3);
  struct Bad {
    double from, to;
    int points;
    const char* word;
  };
  for (const Bad& bad : {Bad{1.0, 4.0, 5, "above 1"}, Bad{4.0, 2.0, 5, "A < B"}, Bad{1.5, std::nan(""), 5, "finite"},
                         Bad{1.5, 4.0, 1, "points"}, Bad{1.5, 4.0, 1001, "points"}, Bad{1.5, 1e9, 5, "at most"}}) {
    const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, volume_curve(nh, bad.from, bad.to, bad.points));
    EXPECT_FALSE(curve.converged);
    EXPECT_EQ(curve.stop, InflationStop::InvalidInput);
    EXPECT_TRUE(curve.points.empty());
    EXPECT_NE(curve.message.find(bad.word), std::string::npos) << curve.message;
  }
  PressureVolumeCurveOptions thin = volume_curve(nh, 1.5, 4.0, 3);
  thin.thickness_mm = -1.0;
  const PressureVolumeCurve curve = trace_pressure_volume_curve(sphere, thin);
  EXPECT_EQ(curve.stop, InflationStop::InvalidInput);
  EXPECT_NE(curve.message.find("thickness"), std::string::npos) << curve.message;
  ASSERT_EQ(curve.points.size(), 3u);
  for (const CurvePoint& point : curve.points) EXPECT_FALSE(point.converged || point.pressure_kpa);
}

TEST(PressureVolumeCurve, SaysWhatTheModelAddedBeyondTheMembrane) {
  // A cap sliver is simulated flipped, and the femur (200 mm, silicone) wrinkles with no stable membrane
  // state on its way to x2, so the sheet's bending goes on; the curve's report says both, as inflate()'s does.
  const PressureVolumeCurve sliver = trace_pressure_volume_curve(
      test::sphere_with_cap_sliver(50.0, 2, 0.001), volume_curve(make(MaterialModel::NeoHookean, 0.3), 1.5, 3.0, 2));
  ASSERT_TRUE(sliver.converged) << sliver.message;
  EXPECT_EQ(sliver.flipped_cap_slivers, 1);
  EXPECT_FALSE(sliver.bending);

  auto femur = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/femur.off");
  ASSERT_TRUE(femur.ok()) << femur.error();
  femur->vertices *= 200.0 / bounding_box_diagonal(femur->vertices);
  const PressureVolumeCurve bent =
      trace_pressure_volume_curve(*femur, volume_curve(*parse_material_spec("silicone"), 1.5, 2.0, 2));
  ASSERT_TRUE(bent.converged) << bent.message;
  EXPECT_TRUE(bent.bending);
  EXPECT_EQ(bent.flipped_cap_slivers, 0);
}

// The curve ends where its walls pass through each other, as a single inflation does (inflate()): past
// that this model, with no contact, follows no balloon. The knot at 20 mm with Neo-Hookean rubber, whose
// strands touch on the way to x8 (Inflation.TheSqpShiftOnlyRemovesWhatTheVolumeConstraintLeavesUnstable).
TEST(PressureVolumeCurve, EndsWhereItsWallsPassThroughEachOther) {
  auto knot = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/knot.off");
  ASSERT_TRUE(knot.ok()) << knot.error();
  knot->vertices *= 20.0 / bounding_box_diagonal(knot->vertices);
  const PressureVolumeCurve curve =
      trace_pressure_volume_curve(*knot, volume_curve(make(MaterialModel::NeoHookean, 0.3), 1.5, 8.0, 5));
  EXPECT_FALSE(curve.converged);
  EXPECT_EQ(curve.stop, InflationStop::PassesThroughItself) << curve.message;
  ASSERT_GE(curve.last_converged_point, 0) << curve.message;
  ASSERT_LT(curve.last_converged_point, 4);
  const CurvePoint& touching = curve.points[static_cast<size_t>(curve.last_converged_point) + 1];
  EXPECT_FALSE(touching.converged);
  EXPECT_FALSE(touching.volume_ratio || touching.pressure_kpa);
  EXPECT_NE(touching.message.find("passes through itself"), std::string::npos) << touching.message;
  EXPECT_NE(curve.message.find("passes through itself"), std::string::npos) << curve.message;
  TriMesh last = *knot;
  last.vertices = curve.last_shape;
  EXPECT_FALSE(mesh_self_intersects(last));
}

// Where the membrane's walls touch, the whole path runs again with the sheet's bending, as inflate() tries
// it: the latex spot (100 mm) at 1 kPa is a slack membrane crumpled through itself at x1.05; bent, it
// inflates without touching.
TEST(PressureVolumeCurve, WhereTheMembranesWallsTouchItRunsAgainWithBending) {
  auto spot = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/spot.obj");
  ASSERT_TRUE(spot.ok()) << spot.error();
  spot->vertices *= 100.0 / bounding_box_diagonal(spot->vertices);
  PressureVolumeCurveOptions options = volume_curve(*parse_material_spec("latex"), 1.0, 1.3, 2);
  options.control = InflationControl::Pressure;
  const PressureVolumeCurve curve = trace_pressure_volume_curve(*spot, options);
  ASSERT_TRUE(curve.converged) << curve.message;
  EXPECT_TRUE(curve.bending);
  for (const CurvePoint& point : curve.points) EXPECT_NEAR(*point.pressure_kpa, point.target, 1e-9 * point.target);
  TriMesh last = *spot;
  last.vertices = curve.last_shape;
  EXPECT_FALSE(mesh_self_intersects(last));
}

}  // namespace
}  // namespace balloon
