#include "design/adjoint_sensitivity.hpp"

#include <gtest/gtest.h>

#include "sensitivity_scene.hpp"

namespace balloon {
namespace {

using design_test::flat;
using design_test::Scene;

class AdjointSensitivityTest : public ::testing::TestWithParam<bool> {};

TEST_P(AdjointSensitivityTest, DesignGradientMatchesCentralDifferences) {
  Scene scene(GetParam());
  const Eigen::VectorXd rest = flat(scene.rest.vertices);
  // J(x) = 1/2 |x - x_goal|^2, x_goal a fixed displacement of the equilibrium (mm^2).
  const Eigen::VectorXd goal = scene.x + 0.5 * scene.direction(11);
  const auto objective = [&](const Eigen::VectorXd& x) { return 0.5 * (x - goal).squaredNorm(); };

  scene.model.set_rest_positions(scene.rest.vertices);
  AdjointSensitivity sensitivity(scene.model, scene.solver);
  ASSERT_TRUE(sensitivity.prepare(rest, scene.x, scene.pressure_mpa));
  const Eigen::VectorXd gradient = sensitivity.gradient(scene.x - goal);
  ASSERT_GT(gradient.norm(), 1e-6) << "a zero gradient would pass any comparison";

  constexpr double STEP_MM = 1e-4;
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::VectorXd d = scene.direction(seed);
    const double plus = objective(scene.equilibrium(rest + STEP_MM * d));
    const double minus = objective(scene.equilibrium(rest - STEP_MM * d));
    const double finite_difference = (plus - minus) / (2.0 * STEP_MM);
    const double analytic = gradient.dot(d);
    EXPECT_NEAR(analytic, finite_difference, 1e-5 * std::abs(finite_difference) + 1e-9)
        << "direction " << seed << ": adjoint " << analytic << ", central difference " << finite_difference;
  }
}

TEST_P(AdjointSensitivityTest, LinearResponseMatchesCentralDifferences) {
  Scene scene(GetParam());
  const Eigen::VectorXd rest = flat(scene.rest.vertices);
  scene.model.set_rest_positions(scene.rest.vertices);
  AdjointSensitivity sensitivity(scene.model, scene.solver);
  ASSERT_TRUE(sensitivity.prepare(rest, scene.x, scene.pressure_mpa));
  const Eigen::VectorXd d = scene.direction(5);
  Eigen::VectorXd dx;
  double dp = 0.0;
  sensitivity.linear_response(d, dx, dp);
  ASSERT_GT(dx.norm(), 1e-6);

  constexpr double STEP_MM = 1e-4;
  double p_plus = 0.0, p_minus = 0.0;
  const Eigen::VectorXd x_plus = scene.equilibrium(rest + STEP_MM * d, &p_plus);
  const Eigen::VectorXd x_minus = scene.equilibrium(rest - STEP_MM * d, &p_minus);
  const Eigen::VectorXd dx_fd = (x_plus - x_minus) / (2.0 * STEP_MM);
  EXPECT_LT((dx - dx_fd).norm(), 1e-5 * dx_fd.norm()) << "|dx| " << dx.norm() << ", |dx_fd| " << dx_fd.norm();
  EXPECT_NEAR(dp, (p_plus - p_minus) / (2.0 * STEP_MM), 1e-5 * std::abs(dp) + 1e-12);
}

INSTANTIATE_TEST_SUITE_P(MembraneAndBending, AdjointSensitivityTest, ::testing::Bool(),
                         [](const auto& case_info) { return case_info.param ? "WithBending" : "MembraneOnly"; });

}  // namespace
}  // namespace balloon
