#include "design/rest_triangle_quality.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/central_differences.hpp"
#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

TriMesh one_right_triangle() {
  TriMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 0, 0, 10, 0, 0, 0, 10, 0;
  mesh.faces.resize(1, 3);
  mesh.faces << 0, 1, 2;
  return mesh;
}

/// The icosphere with every vertex moved by up to `amount` mm along each axis (seeded).
Eigen::VectorXd jittered(const TriMesh& mesh, double amount, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-amount, amount);
  Eigen::VectorXd rest = flat(mesh.vertices);
  for (Eigen::Index i = 0; i < rest.size(); ++i) rest[i] += uniform(random);
  return rest;
}

TEST(RestTriangleQuality, AScaledRotatedCopyIsUndistorted) {
  const TriMesh sphere = design_test::make_icosphere(2, 20.0);
  const RestTriangleQuality quality(sphere.vertices, sphere.faces, 1000.0);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Positions moved = (0.4 * sphere.vertices * rotation.transpose()).rowwise() + Eigen::RowVector3d(5, -3, 8);
  const Eigen::VectorXd rest = flat(moved);
  for (int f = 0; f < sphere.face_count(); ++f) EXPECT_NEAR(quality.distortion(rest, f), 0.0, 1e-12);
  EXPECT_EQ(quality.value(rest), 0.0);
  EXPECT_EQ(quality.distorted_count(rest), 0);
}

TEST(RestTriangleQuality, TheDistortionOfAStretchIsItsClosedForm) {
  // Stretching one leg of a right triangle by s: singular stretches s and 1, M = (s + 1/s) / 2 - 1.
  const TriMesh triangle = one_right_triangle();
  const RestTriangleQuality quality(triangle.vertices, triangle.faces, 2.0);
  for (double s : {0.1, 0.5, 2.0, 4.0, 50.0}) {
    Positions stretched = triangle.vertices;
    stretched(1, 0) *= s;
    const double expected = 0.5 * (s + 1.0 / s) - 1.0;
    EXPECT_NEAR(quality.distortion(flat(stretched), 0), expected, 1e-12 * (1.0 + expected)) << "s = " << s;
    const double excess = std::max(0.0, expected - RestTriangleQuality::THRESHOLD);
    EXPECT_NEAR(quality.value(flat(stretched)), 2.0 * excess * excess, 1e-9 * (1.0 + excess * excess)) << "s = " << s;
  }
  Positions collapsed = triangle.vertices;
  collapsed.row(2) = 0.5 * collapsed.row(1);  // on the opposite edge: no area
  EXPECT_TRUE(std::isinf(quality.value(flat(collapsed))));
}

TEST(RestTriangleQuality, GradientMatchesCentralDifferences) {
  const TriMesh sphere = design_test::make_icosphere(1, 20.0);  // 42 vertices, edges about 12 mm
  const RestTriangleQuality quality(sphere.vertices, sphere.faces, 100.0);
  const Eigen::VectorXd rest = jittered(sphere, 6.0, 7);
  const int distorted = quality.distorted_count(rest);
  ASSERT_GT(distorted, 3) << "some triangles must be past the threshold, or the test checks nothing";
  ASSERT_LT(distorted, sphere.face_count()) << "and some not";
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(rest.size());
  quality.add_gradient(rest, gradient);
  const Eigen::VectorXd expected =
      test::central_difference_gradient([&](const Eigen::VectorXd& y) { return quality.value(y); }, rest, 1e-6);
  ASSERT_GT(expected.norm(), 1e-3);
  EXPECT_LT((gradient - expected).norm(), 1e-6 * expected.norm());
}

TEST(RestTriangleQuality, GaussNewtonProductIsTwiceTheWeightTimesTheSquaredRate) {
  // One triangle: d . (R d) = 2 w (dM/dt)^2 along d, with dM/dt by central differences.
  const TriMesh triangle = one_right_triangle();
  const double weight = 3.0;
  const RestTriangleQuality quality(triangle.vertices, triangle.faces, weight);
  Positions sliver = triangle.vertices;
  sliver(2, 1) = 1.0;  // height 10 -> 1 mm: M = 4.05
  const Eigen::VectorXd rest = flat(sliver);
  ASSERT_GT(quality.distortion(rest, 0), RestTriangleQuality::THRESHOLD);
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 random(seed);
    std::normal_distribution<double> normal;
    Eigen::VectorXd d(9);
    for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = normal(random);
    const double h = 1e-6;
    const double rate = (quality.distortion(rest + h * d, 0) - quality.distortion(rest - h * d, 0)) / (2.0 * h);
    const Eigen::VectorXd product = quality.gauss_newton_times(rest, d);
    EXPECT_NEAR(d.dot(product), 2.0 * weight * rate * rate, 1e-6 * (1.0 + 2.0 * weight * rate * rate));
    // Rank one along the distortion's gradient.
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(9);
    quality.add_gradient(rest, gradient);
    EXPECT_LT((product - (product.dot(gradient) / gradient.squaredNorm()) * gradient).norm(), 1e-9 * product.norm());
  }
  // Below the threshold it is nothing.
  EXPECT_EQ(quality.gauss_newton_times(flat(triangle.vertices), Eigen::VectorXd::Ones(9)).norm(), 0.0);
}

}  // namespace
}  // namespace balloon
