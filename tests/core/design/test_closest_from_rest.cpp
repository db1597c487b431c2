// The design handed back is never worse, inflated from rest, than a rest shape the run already checked
// that way: a final design that inflates farther from the target gives way to that one, with the shape it
// reaches and its figures; a final design that does better stays.
#include "design/closest_from_rest.hpp"

#include <gtest/gtest.h>

#include "design/rest_inflation_check.hpp"
#include "design_test_meshes.hpp"
#include "material/material.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// A 162-vertex sphere of radius 10 mm in silicone inflated from rest to three times its volume is the
/// target, so that sphere is a perfect rest shape; the sphere stretched 10% along x and shrunk 10% along
/// y (the same volume) inflates about 0.15 mm from it on average.
struct TwoRestShapes {
  TriMesh sphere = design_test::make_icosphere(2, 10.0);
  TriMesh stretched = sphere;
  InflationOptions options;
  TriMesh target;

  TwoRestShapes() {
    options.material = *parse_material_spec("silicone");
    options.thickness_mm = 0.5;
    options.control = InflationControl::VolumeRatio;
    options.volume_ratio = 3.0;
    target = TriMesh{inflate(sphere, options).deformed, sphere.faces};
    stretched.vertices.col(0) *= 1.1;
    stretched.vertices.col(1) /= 1.1;
  }

  /// A result whose final rest shape is `final_rest`, checked from rest, and whose closest shape checked
  /// during the run is `checked` (at `checked_error_mm`, iteration 4).
  DesignResult result(const TriMesh& final_rest, const TriMesh& checked, double checked_error_mm) const {
    DesignResult result;
    result.stop = DesignStop::TimeLimit;
    result.message = "time limit reached";
    result.rest = final_rest;
    result.inflated = inflate(final_rest, options).deformed;
    result.avg_error_mm = 0.01;  // the design's own figure on its branch
    result.volume_ratio = options.volume_ratio;
    result.bbox_diag_mm = bounding_box_diagonal(target.vertices);
    result.distance_energy = 1.0;
    result.closest_from_rest = CheckedFromRest{checked.vertices, checked_error_mm, 4};
    result.from_rest = check_inflation_from_rest(final_rest, options, result.inflated, *result.avg_error_mm,
                                                 SurfaceDistance(target), target.vertices);
    return result;
  }
};

TEST(ClosestFromRest, AFinalDesignFartherFromRestGivesWayToTheCheckedOne) {
  const TwoRestShapes shapes;
  DesignResult result = shapes.result(shapes.stretched, shapes.sphere, 1e-9);
  ASSERT_TRUE(result.from_rest->converged) << result.from_rest->message;
  const double final_error = *result.from_rest->avg_error_mm;
  ASSERT_GT(final_error, 0.1);

  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_TRUE(result.rest.vertices.isApprox(shapes.sphere.vertices, 0.0));
  ASSERT_TRUE(result.avg_error_mm && result.max_error_mm && result.avg_error_rel && result.max_error_rel);
  EXPECT_LT(*result.avg_error_mm, 1e-6);  // the sphere inflates onto the target
  EXPECT_LT(*result.max_error_mm, 1e-5);
  EXPECT_LT((result.inflated - shapes.target.vertices).cwiseAbs().maxCoeff(), 1e-5);
  ASSERT_TRUE(result.volume_ratio && result.pressure_kpa && result.residual_norm);
  EXPECT_NEAR(*result.volume_ratio, 3.0, 1e-9);
  EXPECT_FALSE(result.distance_energy) << "never evaluated for the shape handed back";
  EXPECT_EQ(result.stop, DesignStop::TimeLimit);
  EXPECT_FALSE(result.converged);
  EXPECT_NE(result.message.find("the design of iteration 4"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("is handed back"), std::string::npos) << result.message;
  ASSERT_TRUE(result.from_rest->converged && result.from_rest->avg_error_mm && result.from_rest->deviation_mm);
  EXPECT_EQ(*result.from_rest->avg_error_mm, *result.avg_error_mm);
  EXPECT_EQ(*result.from_rest->deviation_mm, 0.0);
  EXPECT_FALSE(result.from_rest->another_shape);
}

TEST(ClosestFromRest, AMatchedDesignThatGivesWayIsNoLongerCalledConverged) {
  const TwoRestShapes shapes;
  DesignResult result = shapes.result(shapes.stretched, shapes.sphere, 1e-9);
  result.stop = DesignStop::Matched;
  result.converged = true;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_TRUE(result.rest.vertices.isApprox(shapes.sphere.vertices, 0.0));
  EXPECT_EQ(result.stop, DesignStop::Stalled);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.message.rfind("stalled: the last design was matched on the branch the design followed", 0), 0u)
      << result.message;
}

TEST(ClosestFromRest, AFinalDesignWithNoEquilibriumFromRestGivesWayToo) {
  const TwoRestShapes shapes;
  DesignResult result = shapes.result(shapes.sphere, shapes.stretched, 0.15);
  // As where the final design's walls touch on its way from rest (the check's figures stay null).
  RestInflationCheck no_equilibrium;
  no_equilibrium.stop = InflationStop::PassesThroughItself;
  no_equilibrium.inflation_message = "its walls touch";
  result.from_rest = no_equilibrium;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_TRUE(result.rest.vertices.isApprox(shapes.stretched.vertices, 0.0));
  ASSERT_TRUE(result.from_rest->converged && result.avg_error_mm);
  EXPECT_NEAR(*result.avg_error_mm, 0.15, 0.05);
  EXPECT_NE(result.message.find("finds no equilibrium (its walls touch)"), std::string::npos) << result.message;

  // Where the check only ran out of time, nothing is known against the final design: it stays.
  DesignResult timed_out = shapes.result(shapes.sphere, shapes.stretched, 0.15);
  RestInflationCheck out_of_time;
  out_of_time.stop = InflationStop::TimeLimit;
  timed_out.from_rest = out_of_time;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, timed_out);
  EXPECT_TRUE(timed_out.rest.vertices.isApprox(shapes.sphere.vertices, 0.0));
}

TEST(ClosestFromRest, AFinalDesignCloserFromRestStays) {
  const TwoRestShapes shapes;
  // The checked shape's recorded error is the stretched sphere's from rest, above the final sphere's.
  DesignResult result = shapes.result(shapes.sphere, shapes.stretched, 0.15);
  const DesignResult before = result;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_TRUE(result.rest.vertices.isApprox(before.rest.vertices, 0.0));
  EXPECT_EQ(result.message, before.message);
  EXPECT_EQ(*result.avg_error_mm, *before.avg_error_mm);
  EXPECT_TRUE(result.distance_energy);
}

TEST(ClosestFromRest, AHandedBackShapeMustStillDoBetterWhenCheckedAgain) {
  const TwoRestShapes shapes;
  // The run recorded the stretched sphere as nearly perfect, but checked again it is not: the final
  // sphere, which is, stays.
  DesignResult result = shapes.result(shapes.sphere, shapes.stretched, 0.0);
  result.from_rest->avg_error_mm = 1e-3;  // the final check found it a little farther than that record
  const Positions final_rest = result.rest.vertices;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_TRUE(result.rest.vertices.isApprox(final_rest, 0.0));
  EXPECT_EQ(result.message, "time limit reached");
}

TEST(ClosestFromRest, ADesignMatchedAtItsStartIsNotHandedItsOwnStartBack) {
  const TwoRestShapes shapes;
  // The final design is the start itself (matched after 0 iterations); its two checks from rest differ
  // in the last digits only.
  DesignResult result = shapes.result(shapes.sphere, shapes.sphere, 0.0);
  result.stop = DesignStop::Matched;
  result.converged = true;
  result.message = "matched";
  result.closest_from_rest->avg_error_mm = *result.from_rest->avg_error_mm * (1.0 - 1e-14);
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, result);
  EXPECT_EQ(result.stop, DesignStop::Matched);
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.message, "matched");
  EXPECT_TRUE(result.distance_energy);

  // Nor does another rest shape that did better by less than a percent replace it.
  DesignResult close_call = shapes.result(shapes.stretched, shapes.sphere, 0.0);
  close_call.closest_from_rest->avg_error_mm = *close_call.from_rest->avg_error_mm * 0.995;
  hand_back_closest_from_rest(shapes.target, SurfaceDistance(shapes.target), shapes.options, close_call);
  EXPECT_TRUE(close_call.rest.vertices.isApprox(shapes.stretched.vertices, 0.0));
  EXPECT_EQ(close_call.message, "time limit reached");
}

}  // namespace
}  // namespace balloon
