#include "design/mold.hpp"
#include "mesh/self_intersection.hpp"
#include "design/target_preparation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "core/design/design_test_meshes.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// Every directed edge appears exactly once and its reverse exactly once (closed, edge-manifold,
/// consistently oriented): checked here independently of validate_balloon_mesh.
void expect_closed_oriented(const TriMesh& mesh) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) ++directed[{mesh.faces(f, k), mesh.faces(f, (k + 1) % 3)}];
  }
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto twin = directed.find({edge.second, edge.first});
    if (count != 1 || twin == directed.end() || twin->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(static_cast<int>(directed.size()), 3 * mesh.face_count());
}

void check_mold(const TriMesh& rest, const Eigen::Vector3d& nozzle, double radius, double length) {
  auto mold = build_mold(rest, nozzle, radius, length);
  ASSERT_TRUE(mold.ok()) << mold.error();
  expect_closed_oriented(*mold);
  TriMesh copy = *mold;
  auto report = validate_balloon_mesh(copy);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_FALSE(report->flipped);
  EXPECT_EQ(report->removed_unreferenced_vertices, 0);
  EXPECT_EQ(report->genus, 0);
  EXPECT_FALSE(mesh_self_intersects(*mold));
  const double rest_volume = enclosed_volume(rest.vertices, rest.faces);
  const double mold_volume = enclosed_volume(mold->vertices, mold->faces);
  // The tube adds about pi r^2 L; the removed cap takes little.
  const double tube = std::numbers::pi * radius * radius * length;
  EXPECT_GT(mold_volume, rest_volume + 0.5 * tube);
  EXPECT_LT(mold_volume, rest_volume + 1.5 * tube);
  // The tube's end reaches `length` beyond the surface along the outward axis.
  const double reach = (mold->vertices.rowwise() - nozzle.transpose()).rowwise().norm().maxCoeff();
  EXPECT_GT(reach, length);
}

TEST(Mold, IcosphereWithTubeAtTheBottom) {
  const TriMesh sphere = design_test::make_icosphere(3, 50.0);
  check_mold(sphere, Eigen::Vector3d(0, 0, -50), 6.0, 20.0);
  // Off-axis nozzle, coarse radius relative to the edge length.
  check_mold(sphere, Eigen::Vector3d(30, 30, 25), 12.0, 15.0);
}

TEST(Mold, SampleMeshes) {
  // Rest shapes come from prepared (remeshed) targets; the cube is already uniform.
  for (const char* name : {"hand_fist.off", "cube_866.off", "retinal_bumpy_blob.off"}) {
    SCOPED_TRACE(name);
    const TriMesh raw = design_test::read_sample_mesh(name);
    ASSERT_GT(raw.vertex_count(), 0);
    TargetPreparationOptions options;
    options.size_mm = 120.0;
    options.resolution = 3000;
    auto prepared = prepare_target(raw, options);
    ASSERT_TRUE(prepared.ok()) << prepared.error();
    const TriMesh& mesh = prepared->mesh;
    int lowest = 0;
    mesh.vertices.col(2).minCoeff(&lowest);
    check_mold(mesh, mesh.vertices.row(lowest).transpose(), 4.0, 15.0);
  }
}

TEST(Mold, RefusesATubeThatWouldCutTheSurface) {
  // The raw hand has 40 mm slivers at its lowest point: the hole is not round and the tube would cut
  // the wrist; the mold is refused with a message instead of a broken print.
  TriMesh hand = design_test::read_sample_mesh("hand_fist.off");
  ASSERT_GT(hand.vertex_count(), 0);
  hand.vertices *= 120.0 / bounding_box_diagonal(hand.vertices);
  int lowest = 0;
  hand.vertices.col(2).minCoeff(&lowest);
  auto mold = build_mold(hand, hand.vertices.row(lowest).transpose(), 4.0, 15.0);
  ASSERT_FALSE(mold.ok());
  EXPECT_NE(mold.error().find("mold:"), std::string::npos);
}

TEST(Mold, RejectsBadArguments) {
  const TriMesh sphere = design_test::make_icosphere(2, 10.0);
  EXPECT_FALSE(build_mold(sphere, Eigen::Vector3d(0, 0, -10), 0.0, 5.0).ok());
  EXPECT_FALSE(build_mold(sphere, Eigen::Vector3d(0, 0, -10), 2.0, -1.0).ok());
  EXPECT_FALSE(build_mold(sphere, Eigen::Vector3d(0, 0, -100), 2.0, 5.0).ok());
  // A tube wider than the balloon leaves no round hole.
  auto huge = build_mold(sphere, Eigen::Vector3d(0, 0, -10), 50.0, 5.0);
  EXPECT_FALSE(huge.ok());
}

}  // namespace
}  // namespace balloon
