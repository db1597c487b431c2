// The design's check of its rest shape inflated from rest, as `balloon simulate` inflates it: the same
// shape (up to a rigid motion) is the design's; a shape farther from the design's than the design's own
// error is another one; an inflation that does not finish leaves every figure null.
#include "design/rest_inflation_check.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "design_test_meshes.hpp"
#include "material/material.hpp"

namespace balloon {
namespace {

/// A 162-vertex sphere of radius 10 mm in silicone, inflated from rest to three times its volume: the
/// shape a maker would get, and the target it is measured against.
struct SphereCheck {
  TriMesh rest = design_test::make_icosphere(2, 10.0);
  InflationOptions options;
  InflationResult inflated;
  TriMesh target;

  SphereCheck() {
    options.material = *parse_material_spec("silicone");
    options.thickness_mm = 0.5;
    options.control = InflationControl::VolumeRatio;
    options.volume_ratio = 3.0;
    inflated = inflate(rest, options);
    target = TriMesh{inflated.deformed, rest.faces};
  }

  RestInflationCheck check(const Positions& design_inflated, double design_avg_error_mm) const {
    return check_inflation_from_rest(rest, options, design_inflated, design_avg_error_mm, SurfaceDistance(target),
                                     target.vertices);
  }
};

TEST(RestInflationCheck, TheDesignsOwnShapeMovedRigidlyIsTheDesignsShape) {
  const SphereCheck sphere;
  ASSERT_TRUE(sphere.inflated.converged) << sphere.inflated.message;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Positions moved = sphere.inflated.deformed * turn.transpose();
  moved.rowwise() += Eigen::RowVector3d(5.0, -2.0, 1.0);

  const RestInflationCheck check = sphere.check(moved, 0.0);
  ASSERT_TRUE(check.converged) << check.message;
  EXPECT_EQ(check.stop, InflationStop::Converged);
  ASSERT_TRUE(check.deviation_mm && check.avg_error_mm && check.max_error_mm && check.avg_error_rel);
  EXPECT_LT(*check.deviation_mm, 1e-6);
  EXPECT_LT(*check.avg_error_mm, 1e-6);  // the target is that very shape
  EXPECT_FALSE(check.another_shape);
  ASSERT_TRUE(check.pressure_kpa);
  EXPECT_NEAR(*check.pressure_kpa, sphere.inflated.pressure_kpa, 1e-9 * sphere.inflated.pressure_kpa);
  EXPECT_EQ(check.unstable_modes, 0);
  EXPECT_NE(check.message.find("takes the design's shape"), std::string::npos) << check.message;
}

TEST(RestInflationCheck, AShapeFartherFromTheDesignsThanItsErrorIsAnotherShape) {
  const SphereCheck sphere;
  ASSERT_TRUE(sphere.inflated.converged) << sphere.inflated.message;
  // The design's shape: the sphere stretched 10% along x and shrunk 10% along y (radius about 14.4 mm),
  // so the shape reached from rest lies about a millimetre from it on average.
  Positions stretched = sphere.inflated.deformed;
  stretched.col(0) *= 1.1;
  stretched.col(1) /= 1.1;

  const RestInflationCheck far = sphere.check(stretched, 0.01);
  ASSERT_TRUE(far.converged) << far.message;
  ASSERT_TRUE(far.deviation_mm);
  EXPECT_GT(*far.deviation_mm, 0.3);
  EXPECT_LT(*far.deviation_mm, 1.5);
  EXPECT_TRUE(far.another_shape);
  EXPECT_NE(far.message.find("takes another shape"), std::string::npos) << far.message;

  // The same shapes, but a design whose own error is larger than their distance: the design's figure
  // already covers the difference.
  const RestInflationCheck near = sphere.check(stretched, 2.0);
  EXPECT_NEAR(*near.deviation_mm, *far.deviation_mm, 1e-12);
  EXPECT_FALSE(near.another_shape);
}

TEST(RestInflationCheck, AnInflationThatDoesNotFinishLeavesEveryFigureNull) {
  SphereCheck sphere;
  ASSERT_TRUE(sphere.inflated.converged) << sphere.inflated.message;
  CancelToken cancelled;
  cancelled.cancel();
  sphere.options.cancel = &cancelled;

  const RestInflationCheck check = sphere.check(sphere.inflated.deformed, 0.0);
  EXPECT_FALSE(check.converged);
  EXPECT_EQ(check.stop, InflationStop::Cancelled);
  EXPECT_FALSE(check.avg_error_mm || check.max_error_mm || check.avg_error_rel || check.pressure_kpa ||
               check.deviation_mm);
  EXPECT_FALSE(check.another_shape);
  EXPECT_NE(check.message.find("did not reach the design's volume"), std::string::npos) << check.message;
}

}  // namespace
}  // namespace balloon
