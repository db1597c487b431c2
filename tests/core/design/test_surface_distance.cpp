#include "design/surface_distance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

using design_test::make_icosphere;

TEST(SurfaceDistance, PointsAtKnownOffsetsFromASphere) {
  const double radius = 50.0;
  const TriMesh sphere = make_icosphere(4, radius);  // 2562 vertices, edge ~ 4 mm
  SurfaceDistance distance(sphere);
  EXPECT_NEAR(distance.bbox_diagonal_mm(), 2.0 * radius * std::sqrt(3.0), 0.5);

  // Random directions at known radii: outside, inside, on the surface.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  const double offsets[] = {5.0, -3.0, 0.0, 20.0};
  Positions points(400, 3);
  Eigen::VectorXd expected(400);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d dir = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    const double offset = offsets[i % 4];
    points.row(i) = (radius + offset) * dir;
    expected(i) = std::abs(offset);
  }
  const Eigen::VectorXd d = distance.distances(points);
  // The inscribed polyhedron lies inside the sphere by at most the sagitta h^2 / (8R) ~ 0.1 mm here.
  const double sagitta = 0.12;
  for (int i = 0; i < 400; ++i) {
    const double offset = offsets[i % 4];
    // The polyhedron is inside the sphere: outside points are a little farther, inside ones nearer.
    if (offset >= 0.0) {
      EXPECT_GE(d(i), expected(i) - 1e-9) << i;
      EXPECT_LE(d(i), expected(i) + sagitta) << i;
    } else {
      EXPECT_LE(d(i), expected(i) + 1e-9) << i;
      EXPECT_GE(d(i), expected(i) - sagitta) << i;
    }
  }
  // Closest points lie on the surface and closest_points agrees with distances().
  Positions closest;
  Eigen::VectorXd d2;
  Eigen::VectorXi faces;
  distance.closest_points(points, closest, &d2, &faces);
  EXPECT_LE((d - d2).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(faces.minCoeff() >= 0 && faces.maxCoeff() < sphere.face_count(), true);
  for (int i = 0; i < 400; ++i) EXPECT_NEAR(closest.row(i).norm(), radius, sagitta);

  // Mesh vertices are at distance 0; stats in mm and relative to the diagonal.
  const SurfaceDistanceStats on = distance.stats(sphere.vertices);
  EXPECT_LE(on.max_mm, 1e-9);
  Positions shell = 1.02 * sphere.vertices;  // every vertex 1 mm outside the vertex sphere
  const SurfaceDistanceStats s = distance.stats(shell);
  EXPECT_NEAR(s.avg_mm, 1.0, 0.01);
  EXPECT_NEAR(s.max_mm, 1.0, 0.01);
  EXPECT_NEAR(s.avg_rel, s.avg_mm / s.bbox_diag_mm, 1e-15);
}

TEST(RigidAlignment, RecoversAKnownRotationAndTranslation) {
  const TriMesh shape = design_test::make_bumpy_sphere(2, 30.0, 0.2);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(2.5, Eigen::Vector3d(-1, 3, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(10, -20, 7);
  RigidTransform motion{r, t};
  const Positions moved = motion.apply(shape.vertices);

  const RigidTransform found = rigid_alignment(shape.vertices, moved);
  EXPECT_LE((found.rotation - r).norm(), 1e-12);
  EXPECT_LE((found.translation - t).norm(), 1e-10);
  EXPECT_NEAR(found.rotation.determinant(), 1.0, 1e-12);
  const Positions back = rigid_align_to(moved, shape.vertices);
  EXPECT_LE((back - shape.vertices).cwiseAbs().maxCoeff(), 1e-10);

  // A mirror image is not a rigid motion: the result is still a rotation.
  Positions mirrored = shape.vertices;
  mirrored.col(0) *= -1.0;
  EXPECT_NEAR(rigid_alignment(mirrored, shape.vertices).rotation.determinant(), 1.0, 1e-12);

  // The error metric after alignment ignores the placement.
  SurfaceDistance distance(shape);
  EXPECT_GT(distance.stats(moved).avg_mm, 1.0);
  EXPECT_LE(distance.aligned_stats(moved, shape.vertices).max_mm, 1e-9);
}

}  // namespace
}  // namespace balloon
