#include "design/thickness_tolerance.hpp"

#include <gtest/gtest.h>

#include "design_test_meshes.hpp"
#include "material/material.hpp"

namespace balloon {
namespace {

struct NominalRun {
  TriMesh rest;
  InflationOptions options;
  InflationResult inflated;
};

NominalRun nominal_sphere() {
  NominalRun run;
  run.rest = design_test::make_icosphere(2, 10.0);  // 162 vertices, radius 10 mm
  run.options.material = *parse_material_spec("silicone");
  run.options.thickness_mm = 0.5;
  run.options.control = InflationControl::VolumeRatio;
  run.options.volume_ratio = 3.0;
  run.inflated = inflate(run.rest, run.options);
  return run;
}

TEST(ThicknessTolerance, DeviationGrowsWithPerturbationAndIsDeterministic) {
  const NominalRun run = nominal_sphere();
  ASSERT_TRUE(run.inflated.converged) << run.inflated.message;
  const ThicknessTolerance first = thickness_tolerance(run.rest, run.options, run.inflated.deformed, 3, 7u);
  ASSERT_EQ(first.levels.size(), 2u);
  EXPECT_DOUBLE_EQ(first.levels[0].perturbation, 0.10);
  EXPECT_DOUBLE_EQ(first.levels[1].perturbation, 0.20);
  for (const ThicknessToleranceLevel& level : first.levels) {
    EXPECT_EQ(level.samples, 3);
    EXPECT_EQ(level.failed_samples, 0);
    // A thickness change of a few % on a ~17 mm sphere moves vertices by well under a mm but clearly more
    // than solver noise (residual tolerance 1e-8 relative).
    EXPECT_GT(level.mean_deviation_mm, 1e-4);
    EXPECT_LT(level.mean_deviation_mm, 5.0);
    EXPECT_GE(level.max_deviation_mm, level.mean_deviation_mm);
  }
  EXPECT_GE(first.levels[1].mean_deviation_mm, first.levels[0].mean_deviation_mm);

  const ThicknessTolerance again = thickness_tolerance(run.rest, run.options, run.inflated.deformed, 3, 7u);
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_NEAR(again.levels[i].mean_deviation_mm, first.levels[i].mean_deviation_mm, 1e-12);

  const ThicknessTolerance other = thickness_tolerance(run.rest, run.options, run.inflated.deformed, 3, 8u);
  EXPECT_NE(other.levels[0].mean_deviation_mm, first.levels[0].mean_deviation_mm);
}

TEST(ThicknessTolerance, ZeroSamplesGivesEmptyLevels) {
  const NominalRun run = nominal_sphere();
  ASSERT_TRUE(run.inflated.converged) << run.inflated.message;
  const ThicknessTolerance none = thickness_tolerance(run.rest, run.options, run.inflated.deformed, 0, 1u);
  ASSERT_EQ(none.levels.size(), 2u);
  EXPECT_EQ(none.levels[0].samples, 0);
  EXPECT_EQ(none.levels[0].mean_deviation_mm, 0.0);
}

}  // namespace
}  // namespace balloon
