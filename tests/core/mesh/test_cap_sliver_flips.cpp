#include "mesh/cap_sliver_flips.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/mesh/mesh_test_helpers.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon {
namespace {

TEST(CapSliverFlips, AThousandthOfADegreeCapIsFlippedWithoutMovingAVertex) {
  const TriMesh mesh = test::sphere_with_cap_sliver(50.0, 2, 0.001);
  ASSERT_LT(min_angle_deg(mesh.vertices, mesh.faces), 0.0011);
  const CapSliverFlips flips = flip_cap_slivers(mesh);
  ASSERT_EQ(flips.flipped_pairs.size(), 1u);
  EXPECT_EQ(flips.flipped_pairs[0][0], mesh.face_count() - 1);  // the cap, with its neighbour across ab
  TriMesh flipped{mesh.vertices, flips.faces};
  ASSERT_TRUE(validate_balloon_mesh(flipped).ok());
  EXPECT_EQ(flipped.vertices, mesh.vertices);
  EXPECT_GT(min_angle_deg(flipped.vertices, flipped.faces), 10.0);  // an icosphere's faces are ~ 55-65 degrees
  // The volume changes by the tetrahedron of the pair's four corners: at most the cap's height over ab
  // (1.1e-4 mm here) times the neighbour's area / 3.
  const Eigen::Vector3i cap = mesh.faces.row(flips.flipped_pairs[0][0]).transpose();
  const Eigen::Vector3d a = mesh.vertices.row(cap[0]).transpose(), b = mesh.vertices.row(cap[1]).transpose(),
                        m = mesh.vertices.row(cap[2]).transpose();
  const double height = (m - a).cross(b - a).norm() / (b - a).norm();
  const Eigen::Vector3i neighbour = mesh.faces.row(flips.flipped_pairs[0][1]).transpose();
  const double neighbour_area = 0.5 * (mesh.vertices.row(neighbour[1]) - mesh.vertices.row(neighbour[0]))
                                          .cross(mesh.vertices.row(neighbour[2]) - mesh.vertices.row(neighbour[0]))
                                          .norm();
  EXPECT_LE(std::abs(enclosed_volume(flipped.vertices, flipped.faces) - enclosed_volume(mesh.vertices, mesh.faces)),
            height * neighbour_area / 3.0);
  for (int f = 0; f < mesh.face_count(); ++f) {
    if (f == flips.flipped_pairs[0][0] || f == flips.flipped_pairs[0][1]) continue;
    EXPECT_EQ(flipped.faces.row(f), mesh.faces.row(f)) << "face " << f << " is not part of the flip";
  }
}

TEST(CapSliverFlips, WellShapedTrianglesAndMildCapsAreLeftAlone) {
  const TriMesh sphere = make_icosphere(10.0, 3);
  const CapSliverFlips none = flip_cap_slivers(sphere);
  EXPECT_TRUE(none.flipped_pairs.empty());
  EXPECT_EQ(none.faces, sphere.faces);
  const TriMesh mild = test::sphere_with_cap_sliver(50.0, 2, 0.5);
  EXPECT_TRUE(flip_cap_slivers(mild).flipped_pairs.empty());
}

TEST(CapSliverFlips, TheAnchorsCapIsTheOnlyFlipOfItsMesh) {
  auto anchor = read_mesh(test::sample_mesh("anchor_dense.off"));
  ASSERT_TRUE(anchor.ok()) << anchor.error();
  EXPECT_LT(min_angle_deg(anchor->vertices, anchor->faces), 0.001);
  const CapSliverFlips flips = flip_cap_slivers(*anchor);
  EXPECT_EQ(flips.flipped_pairs.size(), 1u);
  TriMesh flipped{anchor->vertices, flips.faces};
  ASSERT_TRUE(validate_balloon_mesh(flipped).ok());
  EXPECT_GT(min_angle_deg(flipped.vertices, flipped.faces), 0.01);  // its needles stay: no diagonal to swap
}

}  // namespace
}  // namespace balloon
