// Inverse design against a known answer (paper Fig. 5): inflate a known rest shape to get a target,
// design from that target, and the designed balloon's inflation must match it.
#include <gtest/gtest.h>

#include <cstdio>

#include "design/balloon_design.hpp"
#include "mesh/icosphere.hpp"
#include "solve/inflation.hpp"

namespace balloon {
namespace {

TEST(BalloonDesign, RecoversTheBalloonOfAnInflatedEllipsoid) {
  TriMesh rest = make_icosphere(20.0, 3);  // 642 vertices
  for (int v = 0; v < rest.vertex_count(); ++v) {
    rest.vertices(v, 0) *= 1.6;
    rest.vertices(v, 2) *= 0.8;
  }
  InflationOptions inflation;
  inflation.material = *parse_material_spec("silicone");
  inflation.volume_ratio = 6.0;
  const InflationResult inflated = inflate(rest, inflation);
  ASSERT_TRUE(inflated.converged) << inflated.message;
  TriMesh target = rest;
  target.vertices = inflated.deformed;

  DesignOptions options;
  options.material = inflation.material;
  options.volume_ratio = 6.0;
  options.max_time_s = 120;
  const DesignResult design = design_balloon(target, options);
  ASSERT_FALSE(design.log.empty()) << design.message;
  EXPECT_TRUE(design.rest.vertices.allFinite());
  // The downscaled target inflates visibly wrong; the design must be far better.
  EXPECT_GT(design.baseline_avg_error_mm, 10.0 * design.avg_error_mm) << design.message;
  EXPECT_LT(design.avg_error_rel, 1e-3) << design.message << " after " << design.iterations << " iterations";
  EXPECT_NEAR(design.volume_ratio, 6.0, 1e-3);
  EXPECT_TRUE(design.converged) << design.message;
  std::printf("ellipsoid design: %d iterations, %.2f s, avg error %.3g mm (baseline %.3g mm), %s\n", design.iterations,
              design.time_s, design.avg_error_mm, design.baseline_avg_error_mm, design.message.c_str());
}

TEST(BalloonDesign, AugmentedLagrangianImprovesOnTheStartAndEndsInEquilibrium) {
  TriMesh rest = make_icosphere(20.0, 2);  // 162 vertices
  for (int v = 0; v < rest.vertex_count(); ++v) rest.vertices(v, 0) *= 1.6;
  InflationOptions inflation;
  inflation.material = *parse_material_spec("silicone");
  inflation.volume_ratio = 6.0;
  const InflationResult inflated = inflate(rest, inflation);
  ASSERT_TRUE(inflated.converged) << inflated.message;
  TriMesh target = rest;
  target.vertices = inflated.deformed;

  DesignOptions options;
  options.material = inflation.material;
  options.volume_ratio = 6.0;
  options.method = DesignMethod::AugmentedLagrangian;
  options.max_time_s = 8;
  const DesignResult design = design_balloon(target, options);
  ASSERT_FALSE(design.log.empty()) << design.message;
  EXPECT_EQ(design.method, DesignMethod::AugmentedLagrangian);
  EXPECT_LT(design.avg_error_mm, 0.9 * design.baseline_avg_error_mm) << design.message;
  // Reported errors are those of a true equilibrium of the designed rest shape.
  EXPECT_LT(design.residual_norm, 1e-6 * design.pressure_kpa * 1e-3 * 4e4) << design.message;
  std::printf("alm ellipsoid: %d iterations, %.2f s, avg error %.3g mm (baseline %.3g mm), %s\n", design.iterations,
              design.time_s, design.avg_error_mm, design.baseline_avg_error_mm, design.message.c_str());
}

TEST(BalloonDesign, BadOptionsAreReportedNotThrown) {
  const TriMesh target = make_icosphere(20.0, 2);
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.thickness_mm = -1;
  const DesignResult design = design_balloon(target, options);
  EXPECT_FALSE(design.converged);
  EXPECT_NE(design.message.find("thickness"), std::string::npos);
}

}  // namespace
}  // namespace balloon
