#include "design/rest_hinge_fold.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/central_differences.hpp"
#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

/// Two triangles on the hinge (0,0,0)-(10,0,0): (0, 1, 2) in the plane z = 0 and (1, 0, 3) whose far corner
/// is turned by `angle` about the hinge out of that plane. As DistanceEnergy's reference, flat (angle 0).
struct TwoTriangles {
  TriMesh mesh;
  explicit TwoTriangles(double angle) {
    mesh.vertices.resize(4, 3);
    mesh.vertices << 0, 0, 0, 10, 0, 0, 5, 8, 0, 5, -8 * std::cos(angle), 8 * std::sin(angle);
    mesh.faces.resize(2, 3);
    mesh.faces << 0, 1, 2, 1, 0, 3;
  }
};

TEST(RestHingeFold, NothingUpToARightAngleThenABarrierToAFullFold) {
  const TwoTriangles start(0.0);
  const DistanceEnergy hinges(start.mesh.vertices, start.mesh.faces, 0.0, 1.0);
  ASSERT_EQ(hinges.hinge_count(), 1);
  const double weight = 5.0;
  const RestHingeFold fold(hinges, weight);
  const double share = weight * 10.0 / hinges.rest_lengths().sum();  // the hinge's length over all edges'
  double previous = -1.0;
  for (double angle : {0.0, 0.3, 1.5, 1.7, 2.5, 3.0, 3.13}) {
    for (double sign : {1.0, -1.0}) {
      const Eigen::VectorXd rest = flat(TwoTriangles(sign * angle).mesh.vertices);
      EXPECT_NEAR(fold.turn(rest, 0), angle, 1e-9) << angle;
      const double ratio = std::max(0.0, (angle - RestHingeFold::THRESHOLD) / (M_PI - angle));
      EXPECT_NEAR(fold.value(rest), share * ratio * ratio, 1e-9 * (1.0 + share * ratio * ratio)) << angle;
      EXPECT_EQ(fold.folded_count(rest), angle > RestHingeFold::THRESHOLD ? 1 : 0);
    }
    const double value = fold.value(flat(TwoTriangles(angle).mesh.vertices));
    EXPECT_GE(value, previous);  // grows with the turn
    previous = value;
  }
  EXPECT_GT(previous, 1e3 * share) << "unbounded towards a full fold";
}

TEST(RestHingeFold, GradientMatchesCentralDifferences) {
  const TriMesh sphere = design_test::make_icosphere(1, 20.0);  // 42 vertices
  const DistanceEnergy hinges(sphere.vertices, sphere.faces, 0.0, 1.0);
  const RestHingeFold fold(hinges, 100.0);
  // Jitter until some hinges have turned past a right angle, and none near a full fold.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  Eigen::VectorXd rest = flat(sphere.vertices);
  for (Eigen::Index i = 0; i < rest.size(); ++i) rest[i] += uniform(random);
  int folded = 0;
  double largest = 0.0;
  for (int h = 0; h < hinges.hinge_count(); ++h) {
    folded += fold.turn(rest, h) > RestHingeFold::THRESHOLD;
    largest = std::max(largest, fold.turn(rest, h));
  }
  ASSERT_GE(folded, 2) << "some hinges must be past the threshold, or the test checks nothing";
  ASSERT_LT(largest, 3.0);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(rest.size());
  fold.add_gradient(rest, gradient);
  const Eigen::VectorXd expected =
      test::central_difference_gradient([&](const Eigen::VectorXd& y) { return fold.value(y); }, rest, 1e-6);
  ASSERT_GT(expected.norm(), 1e-3);
  EXPECT_LT((gradient - expected).norm(), 1e-6 * expected.norm());
}

TEST(RestHingeFold, GaussNewtonProductIsTwiceTheWeightTimesTheSquaredRate) {
  // One hinge: value = w r^2, so r = sqrt(value / w) and d . (R d) = 2 w (dr/dt)^2 along d.
  const TwoTriangles start(0.0);
  const DistanceEnergy hinges(start.mesh.vertices, start.mesh.faces, 0.0, 1.0);
  const RestHingeFold fold(hinges, 5.0);
  const double share = 5.0 * 10.0 / hinges.rest_lengths().sum();
  const Eigen::VectorXd rest = flat(TwoTriangles(2.2).mesh.vertices);
  ASSERT_GT(fold.turn(rest, 0), RestHingeFold::THRESHOLD);
  const auto ratio = [&](const Eigen::VectorXd& y) { return std::sqrt(fold.value(y) / share); };
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 random(seed);
    std::normal_distribution<double> normal;
    Eigen::VectorXd d(12);
    for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = normal(random);
    const double h = 1e-6;
    const double rate = (ratio(rest + h * d) - ratio(rest - h * d)) / (2.0 * h);
    const double expected = 2.0 * share * rate * rate;
    EXPECT_NEAR(d.dot(fold.gauss_newton_times(rest, d)), expected, 1e-6 * (1.0 + expected));
  }
  EXPECT_EQ(fold.gauss_newton_times(flat(start.mesh.vertices), Eigen::VectorXd::Ones(12)).norm(), 0.0);
}

}  // namespace
}  // namespace balloon
