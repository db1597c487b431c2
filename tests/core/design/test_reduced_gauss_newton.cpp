#include "design/reduced_gauss_newton.hpp"

#include <gtest/gtest.h>

#include "sensitivity_scene.hpp"

namespace balloon {
namespace {

using design_test::flat;
using design_test::Scene;

/// The direction solves the Gauss-Newton system of the reduced objective J(x(rest)) = 1/2 |x - goal|^2,
/// A d = -g with A = P J^T J P: checked along random directions e against the sensitivity J taken by
/// central differences of equilibria, e^T A d = (J e)_fd . (J d)_fd = -e^T g.
TEST(ReducedGaussNewton, DirectionSolvesTheGaussNewtonSystemOfFiniteDifferenceSensitivities) {
  Scene scene;
  const Eigen::VectorXd rest = flat(scene.rest.vertices);
  const Eigen::VectorXd goal = scene.x + 0.5 * scene.direction(11);
  scene.model.set_rest_positions(scene.rest.vertices);
  AdjointSensitivity sensitivity(scene.model, scene.solver);
  ASSERT_TRUE(sensitivity.prepare(rest, scene.x, scene.pressure_mpa));

  const std::vector<bool> rest_free(static_cast<size_t>(rest.size()), true);
  const Eigen::VectorXd w = scene.model.volume_gradient(rest);
  const auto project = [&](Eigen::VectorXd d) { return Eigen::VectorXd(d - (d.dot(w) / w.squaredNorm()) * w); };
  const Eigen::VectorXd gradient = project(sensitivity.gradient(scene.x - goal));
  ASSERT_GT(gradient.norm(), 1e-6) << "a zero gradient would pass any comparison";

  const auto identity = [](const Eigen::VectorXd& v) { return v; };
  const GaussNewtonDirection step = reduced_gauss_newton_direction(
      sensitivity, identity, gradient, rest_free, w, [](const Eigen::VectorXd& q) { return q; }, 500, 1e-12);
  ASSERT_TRUE(step.descent);
  ASSERT_GT(step.direction.norm(), 1e-6);
  EXPECT_LT(std::abs(step.direction.dot(w)), 1e-9 * step.direction.norm() * w.norm()) << "the rest volume is held";

  constexpr double STEP_MM = 1e-4;
  const auto sensitivity_fd = [&](const Eigen::VectorXd& d) {
    return Eigen::VectorXd((scene.equilibrium(rest + STEP_MM * d) - scene.equilibrium(rest - STEP_MM * d)) /
                           (2.0 * STEP_MM));
  };
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
/// (`gauss_newton_model_decrease`): checked with J d by central differences of equilibria.
TEST(ReducedGaussNewton, ATruncatedDirectionsCurvatureIsMinusItsSlope) {
  Scene scene;
  const Eigen::VectorXd rest = flat(scene.rest.vertices);
  const Eigen::VectorXd goal = scene.x + 0.5 * scene.direction(11);
  scene.model.set_rest_positions(scene.rest.vertices);
  AdjointSensitivity sensitivity(scene.model, scene.solver);
  ASSERT_TRUE(sensitivity.prepare(rest, scene.x, scene.pressure_mpa));
  const std::vector<bool> rest_free(static_cast<size_t>(rest.size()), true);
  const Eigen::VectorXd w = scene.model.volume_gradient(rest);
  const Eigen::VectorXd raw = sensitivity.gradient(scene.x - goal);
  const Eigen::VectorXd gradient = raw - (raw.dot(w) / w.squaredNorm()) * w;
  const auto identity = [](const Eigen::VectorXd& v) { return v; };
  const GaussNewtonDirection step = reduced_gauss_newton_direction(sensitivity, identity, gradient, rest_free, w,
                                                                   identity, 3, 1e-12);
  ASSERT_EQ(step.cg_iterations, 3) << "cut off before it converged";
  ASSERT_TRUE(step.descent);
  constexpr double STEP_MM = 1e-4;
  const Eigen::VectorXd response =
      (scene.equilibrium(rest + STEP_MM * step.direction) - scene.equilibrium(rest - STEP_MM * step.direction)) /
      (2.0 * STEP_MM);
  const double slope = step.direction.dot(gradient);
  EXPECT_NEAR(response.squaredNorm(), -slope, 1e-4 * std::abs(slope));
}

}  // namespace
}  // namespace balloon
