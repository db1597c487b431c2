#include "mesh/self_intersection.hpp"

#include <gtest/gtest.h>

#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

TEST(SelfIntersection, SphereIsCleanTwoOverlappingSpheresAreNot) {
  const TriMesh sphere = design_test::make_icosphere(2, 10.0);
  EXPECT_FALSE(mesh_self_intersects(sphere));
  // Two copies 5 mm apart overlap.
  TriMesh two;
  const int n = sphere.vertex_count();
  two.vertices.resize(2 * n, 3);
  two.vertices.topRows(n) = sphere.vertices;
  two.vertices.bottomRows(n) = sphere.vertices.rowwise() + Eigen::RowVector3d(5, 0, 0);
  two.faces.resize(2 * sphere.face_count(), 3);
  two.faces.topRows(sphere.face_count()) = sphere.faces;
  two.faces.bottomRows(sphere.face_count()) = sphere.faces.array() + n;
  EXPECT_TRUE(mesh_self_intersects(two));
  // Moved 25 mm apart they do not.
  two.vertices.bottomRows(n) = sphere.vertices.rowwise() + Eigen::RowVector3d(25, 0, 0);
  EXPECT_FALSE(mesh_self_intersects(two));
}

}  // namespace
}  // namespace balloon
