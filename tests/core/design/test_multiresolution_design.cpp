// Coarse-to-fine design: the field transfer between resolutions, and a design that runs a coarse stage
// and continues from it at full resolution.
#include <gtest/gtest.h>

#include <stdexcept>

#include "design/balloon_design.hpp"
#include "design/multiresolution_design.hpp"
#include "design/surface_transfer.hpp"
#include "design_test_meshes.hpp"
#include "mesh/icosphere.hpp"

namespace balloon {
namespace {

/// A linear field f(p) = A p + b (mm).
Positions linear_field(const Positions& points) {
  Eigen::Matrix3d a;
  a << 0.3, -0.1, 0.05, 0.2, 0.4, -0.3, -0.05, 0.1, 0.25;
  const Eigen::RowVector3d b(1.0, -2.0, 0.5);
  return (points * a.transpose()).rowwise() + b;
}

TEST(SurfaceTransfer, ReproducesALinearFieldOnTheSurface) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  // Points on the surface: the vertices, and a point inside each face (barycentric 0.2, 0.3, 0.5).
  Positions points(sphere.vertex_count() + sphere.face_count(), 3);
  points.topRows(sphere.vertex_count()) = sphere.vertices;
  for (int f = 0; f < sphere.face_count(); ++f)
    points.row(sphere.vertex_count() + f) = 0.2 * sphere.vertices.row(sphere.faces(f, 0)) +
                                            0.3 * sphere.vertices.row(sphere.faces(f, 1)) +
                                            0.5 * sphere.vertices.row(sphere.faces(f, 2));
  const Positions carried = transfer_vertex_field(sphere, linear_field(sphere.vertices), points);
  EXPECT_LT((carried - linear_field(points)).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(SurfaceTransfer, RefusesAFieldOfTheWrongSize) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  EXPECT_THROW(transfer_vertex_field(sphere, Positions::Zero(3, 3), sphere.vertices), std::invalid_argument);
}

TEST(MultiresolutionDesign, CarriesTheCoarseRestShapeAndKeepsTheFullResolutionBaseline) {
  const TriMesh target = design_test::inflated_ellipsoid_target();  // a known answer, 642 vertices
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 6.0;
  options.max_time_s = 120;
  options.coarse_vertices = 200;
  ASSERT_TRUE(runs_coarse_to_fine(target, options));
  const DesignResult design = design_balloon(target, options);
  ASSERT_TRUE(design.coarse_stage.has_value());
  const CoarseStage& coarse = *design.coarse_stage;
  EXPECT_GT(coarse.vertices, 100);
  EXPECT_LT(coarse.vertices, 320);
  EXPECT_GE(coarse.iterations, 1);
  EXPECT_TRUE(coarse.carried) << "the carried rest shape of a smooth ellipsoid inflates";
  EXPECT_FALSE(design.resumed_from_iteration.has_value()) << "a coarse stage is not a resumed job";
  ASSERT_FALSE(design.log.empty());
  EXPECT_GE(design.log.front().time_s, coarse.time_s) << "times include the coarse stage";
  EXPECT_GT(design.log.back().iteration, coarse.iterations) << "iterations go on from the coarse count";
  EXPECT_EQ(design.rest.vertex_count(), target.vertex_count());
  // The baseline is the full-resolution start's, and the design ends far better than it.
  EXPECT_GT(design.baseline_avg_error_mm.value(), 10.0 * design.avg_error_mm.value()) << design.message;
  EXPECT_NEAR(design.volume_ratio.value(), 6.0, 1e-3);
}

TEST(MultiresolutionDesign, IsLeftOutWhereItCannotApply) {
  const TriMesh target = make_icosphere(20.0, 3);  // 642 vertices
  DesignOptions options;
  options.coarse_vertices = 200;
  EXPECT_TRUE(runs_coarse_to_fine(target, options));
  options.coarse_vertices = 400;  // less than twice as many vertices: no gain
  EXPECT_FALSE(runs_coarse_to_fine(target, options));
  options.coarse_vertices = 200;
  options.nozzle_vertices = {0};  // names full-resolution vertices
  EXPECT_FALSE(runs_coarse_to_fine(target, options));
  options.nozzle_vertices.clear();
  options.method = DesignMethod::AugmentedLagrangian;
  EXPECT_FALSE(runs_coarse_to_fine(target, options));
  options.method = DesignMethod::Adjoint;
  options.coarse_vertices = 0;  // the default
  EXPECT_FALSE(runs_coarse_to_fine(target, options));
}

}  // namespace
}  // namespace balloon
