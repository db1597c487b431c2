#include "design/reduced_gauss_newton.hpp"

#include <gtest/gtest.h>

#include "sensitivity_scene.hpp"

namespace balloon {
namespace {

using design_test::flat;
using design_test::Scene;

/// The reduced objective J(x(rest)) = 1/2 |x - goal|^2 on the sensitivity scene: its projected design
/// gradient (rest volume held), and its Gauss-Newton directions with the identity as H and preconditioner.
class ReducedGaussNewton : public ::testing::Test {
 protected:
  void SetUp() override {
    scene.model.set_rest_positions(scene.rest.vertices);
    ASSERT_TRUE(sensitivity.prepare(rest, scene.x, scene.pressure_mpa));
    gradient = project(sensitivity.gradient(scene.x - (scene.x + 0.5 * scene.direction(11))));
    ASSERT_GT(gradient.norm(), 1e-6) << "a zero gradient would pass any comparison";
  }

  Eigen::VectorXd project(const Eigen::VectorXd& d) const { return d - (d.dot(w) / w.squaredNorm()) * w; }

  GaussNewtonDirection direction(int max_iterations) const {
    const auto identity = [](const Eigen::VectorXd& v) { return v; };
    const std::vector<bool> rest_free(static_cast<size_t>(rest.size()), true);
    return reduced_gauss_newton_direction(sensitivity, identity, gradient, rest_free, w, identity, max_iterations,
                                          1e-12);
  }

  /// J d by central differences of equilibria.
  Eigen::VectorXd sensitivity_fd(const Eigen::VectorXd& d) {
    constexpr double STEP_MM = 1e-4;
    return (scene.equilibrium(rest + STEP_MM * d) - scene.equilibrium(rest - STEP_MM * d)) / (2.0 * STEP_MM);
  }

  Scene scene;
  const Eigen::VectorXd rest = flat(scene.rest.vertices);
  const Eigen::VectorXd w = scene.model.volume_gradient(rest);
  AdjointSensitivity sensitivity{scene.model, scene.solver};
  Eigen::VectorXd gradient;
};

/// The direction solves the Gauss-Newton system A d = -g with A = P J^T J P: checked along random
/// directions e against the sensitivity J taken by central differences of equilibria,
/// e^T A d = (J e)_fd . (J d)_fd = -e^T g.
TEST_F(ReducedGaussNewton, DirectionSolvesTheGaussNewtonSystemOfFiniteDifferenceSensitivities) {
  const GaussNewtonDirection step = direction(500);
  ASSERT_TRUE(step.descent);
  ASSERT_GT(step.direction.norm(), 1e-6);
  EXPECT_LT(std::abs(step.direction.dot(w)), 1e-9 * step.direction.norm() * w.norm()) << "the rest volume is held";
  const Eigen::VectorXd response = sensitivity_fd(step.direction);
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::VectorXd e = project(scene.direction(seed));
    const double model = sensitivity_fd(e).dot(response);
    EXPECT_NEAR(model, -e.dot(gradient), 1e-4 * std::abs(e.dot(gradient)) + 1e-9)
        << "direction " << seed << ": e^T A d " << model << ", -e^T g " << -e.dot(gradient);
  }
  std::printf("Gauss-Newton direction: %d CG iterations\n", step.cg_iterations);
}

/// A conjugate-gradient iterate from zero, even one cut off after a few iterations, has d^T A d = -g^T d,
/// which is what the design's trust region takes the Gauss-Newton model's predicted decrease from
/// (`gauss_newton_model_decrease`).
TEST_F(ReducedGaussNewton, ATruncatedDirectionsCurvatureIsMinusItsSlope) {
  const GaussNewtonDirection step = direction(3);
  ASSERT_EQ(step.cg_iterations, 3) << "cut off before it converged";
  ASSERT_TRUE(step.descent);
  const double slope = step.direction.dot(gradient);
  EXPECT_NEAR(sensitivity_fd(step.direction).squaredNorm(), -slope, 1e-4 * std::abs(slope));
}

}  // namespace
}  // namespace balloon
