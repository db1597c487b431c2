#include "design/target_preparation.hpp"

#include <gtest/gtest.h>

#include "core/design/design_test_meshes.hpp"
#include "design/surface_distance.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

TEST(TargetPreparation, RemeshesTheSliveryHand) {
  const TriMesh hand = design_test::read_sample_mesh("hand_fist.off");
  ASSERT_GT(hand.vertex_count(), 0);
  TargetPreparationOptions options;
  options.size_mm = 120.0;
  options.resolution = 4000;
  auto prepared = prepare_target(hand, options);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  const PreparedTarget& p = *prepared;
  RecordProperty("summary", p.summary);
  std::printf("%s\n", p.summary.c_str());

  EXPECT_TRUE(p.remeshed);
  EXPECT_EQ(p.vertices_before, 1197);
  EXPECT_NEAR(p.vertices_after, 4000, 0.2 * 4000);
  EXPECT_LT(p.min_angle_before_deg, 1.0);
  EXPECT_GT(p.min_angle_after_deg, 10.0);
  EXPECT_NEAR(p.bbox_diag_mm, 120.0, 1.0);
  EXPECT_NE(p.summary.find("remeshed from 1197"), std::string::npos);

  TriMesh copy = p.mesh;
  auto check = validate_balloon_mesh(copy);
  ASSERT_TRUE(check.ok()) << check.error();
  EXPECT_FALSE(check->flipped);
  EXPECT_EQ(check->genus, 0);

  // The remeshed surface stays on the scaled input surface.
  TriMesh scaled = hand;
  scaled.vertices *= p.scale_factor;
  SurfaceDistance to_input(scaled);
  EXPECT_LT(to_input.stats(p.mesh.vertices).max_rel, 0.01);

  // Deterministic.
  auto again = prepare_target(hand, options);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->mesh.faces, p.mesh.faces);
  EXPECT_EQ(again->mesh.vertices, p.mesh.vertices);
}

TEST(TargetPreparation, LeavesAFineMeshAlone) {
  const TriMesh sphere = design_test::make_icosphere(4, 1.0);  // 2562 vertices, min angle ~ 50 deg
  TargetPreparationOptions options;
  options.size_mm = 100.0;
  options.resolution = 3000;
  auto prepared = prepare_target(sphere, options);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  EXPECT_FALSE(prepared->remeshed);
  EXPECT_EQ(prepared->mesh.faces, sphere.faces);
  EXPECT_NEAR(prepared->scale_factor, 100.0 / (2.0 * std::sqrt(3.0)), 1e-6);
  EXPECT_NEAR(prepared->bbox_diag_mm, 100.0, 1e-9);
  EXPECT_FALSE(prepared->self_intersecting);

  // Same mesh, far from the asked resolution: remeshed.
  options.resolution = 600;
  auto coarse = prepare_target(sphere, options);
  ASSERT_TRUE(coarse.ok()) << coarse.error();
  EXPECT_TRUE(coarse->remeshed);
  EXPECT_NEAR(coarse->vertices_after, 600, 0.2 * 600);
}

TEST(TargetPreparation, RejectsBadInput) {
  TriMesh open = design_test::make_icosphere(1, 1.0);
  open.faces.conservativeResize(open.faces.rows() - 1, 3);
  auto result = prepare_target(open, {});
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("target mesh"), std::string::npos) << result.error();

  TargetPreparationOptions bad;
  bad.size_mm = -1.0;
  EXPECT_FALSE(prepare_target(design_test::make_icosphere(1, 1.0), bad).ok());
}

}  // namespace
}  // namespace balloon
