// The design's check from rest on a thread of its own: the same result as inflating in the caller's
// thread, and stopped by the caller's cancel token or by abandoning it.
#include <gtest/gtest.h>

#include "design/background_inflation.hpp"
#include "design_test_meshes.hpp"

namespace balloon {
namespace {

/// A 642-vertex sphere of radius 20 mm inflated four-fold with latex (past its pressure maximum).
InflationOptions latex_to_four(const CancelToken* cancel) {
  InflationOptions options;
  options.material = *parse_material_spec("latex");
  options.volume_ratio = 4.0;
  options.cancel = cancel;
  return options;
}

TEST(BackgroundInflation, GivesTheInflationTheCallersThreadGives) {
  const TriMesh rest = design_test::make_bumpy_sphere(3, 20.0, 0.05);
  const InflationResult here = inflate(rest, latex_to_four(nullptr));
  ASSERT_TRUE(here.converged) << here.message;

  BackgroundInflation background;
  EXPECT_FALSE(background.running());
  background.start(rest, latex_to_four(nullptr));
  EXPECT_TRUE(background.running());
  const InflationResult there = background.wait();
  EXPECT_FALSE(background.running());
  ASSERT_TRUE(there.converged) << there.message;
  // The same operations in the same order: the same numbers.
  EXPECT_EQ(there.pressure_kpa, here.pressure_kpa);
  EXPECT_EQ((there.deformed - here.deformed).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BackgroundInflation, TheCallersCancelTokenStopsIt) {
  CancelToken cancel;
  cancel.cancel();
  BackgroundInflation background;
  background.start(design_test::make_bumpy_sphere(3, 20.0, 0.05), latex_to_four(&cancel));
  const InflationResult result = background.wait();
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.stop, InflationStop::Cancelled) << result.message;
}

TEST(BackgroundInflation, AbandonedItEndsAndCanStartAgain) {
  BackgroundInflation background;
  background.abandon();  // nothing running: nothing to do
  background.start(design_test::make_bumpy_sphere(4, 20.0, 0.05), latex_to_four(nullptr));
  background.abandon();
  EXPECT_FALSE(background.running());
  background.start(design_test::make_bumpy_sphere(3, 20.0, 0.05), latex_to_four(nullptr));
  EXPECT_TRUE(background.wait().converged);
}

}  // namespace
}  // namespace balloon
