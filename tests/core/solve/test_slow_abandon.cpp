// NewtonSettings::abandon_slow: a volume solve that converges quadratically is left alone, and one that
// creeps stops early with NewtonStop::Slow instead of running to its iteration limit; with
// stagnation_tolerance_factor, one that stagnates within that many force tolerances is converged.
#include <gtest/gtest.h>

#include <cmath>

#include "ellipsoid_fixture.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// Solves the ellipsoid to `ratio` times its volume from `start_scale` times its rest shape.
NewtonReport solve(double ratio, double start_scale, bool abandon_slow, double stagnation_factor = 0.0) {
  test::EllipsoidSolve ellipsoid;
  NewtonSettings settings;
  settings.relative_tolerance = 1e-8;
  settings.max_iterations = 200;
  settings.abandon_slow = abandon_slow;
  settings.stagnation_tolerance_factor = stagnation_factor;
  Eigen::VectorXd x = flat(ellipsoid.mesh.vertices) * start_scale;
  double pressure = 0.0;
  return ellipsoid.solver.solve_volume(x, pressure, ratio * enclosed_volume(ellipsoid.mesh.vertices, ellipsoid.mesh.faces),
                                       settings);
}

TEST(SlowAbandon, AQuadraticSolveIsLeftAlone) {
  // From the shape scaled to the target volume: a few Newton steps.
  const NewtonReport report = solve(3.0, std::cbrt(3.0), true);
  EXPECT_TRUE(report.converged) << report.message;
  EXPECT_EQ(report.stop, NewtonStop::Converged);
}

TEST(SlowAbandon, ACreepingSolveStopsEarlyAndSaysSo) {
  // From the rest shape straight to eight times its volume: a long, damped way.
  const NewtonReport plain = solve(8.0, 1.0, false);
  ASSERT_GE(plain.iterations, 8) << "the case is no longer slow: " << plain.message;
  const NewtonReport abandoned = solve(8.0, 1.0, true);
  EXPECT_FALSE(abandoned.converged);
  EXPECT_EQ(abandoned.stop, NewtonStop::Slow);
  EXPECT_STREQ(newton_stop_word(abandoned.stop), "slow");
  EXPECT_GE(abandoned.iterations, 4);  // never before the fourth iteration
  EXPECT_LT(abandoned.iterations, plain.iterations);
}

TEST(SlowAbandon, ACreepingSolveFarAboveTheToleranceIsNotTakenForStagnation) {
  // Its residual when abandoned is far above 10 force tolerances: still slow, not converged.
  const NewtonReport abandoned = solve(8.0, 1.0, true, 10.0);
  EXPECT_FALSE(abandoned.converged);
  EXPECT_EQ(abandoned.stop, NewtonStop::Slow);
  EXPECT_EQ(abandoned.stagnated_at, 0.0);
}

/// The ellipsoid at its rest volume with Pipkin's tension field: zero pressure, every triangle at the
/// relaxed energy's kink between slack and taut, where Newton stagnates far above a 1e-10 tolerance.
constexpr int SLACK_BOUNDARY_ITERATIONS = 60;

NewtonReport solve_at_the_slack_boundary(double stagnation_factor, double* volume_error = nullptr,
                                         bool abandon_slow = true) {
  test::EllipsoidSolve ellipsoid;
  ellipsoid.model.set_tension_field(true);
  NewtonSettings settings;
  settings.relative_tolerance = 1e-10;
  settings.max_iterations = SLACK_BOUNDARY_ITERATIONS;
  settings.abandon_slow = abandon_slow;
  settings.stagnation_tolerance_factor = stagnation_factor;
  Eigen::VectorXd x = flat(ellipsoid.mesh.vertices);
  double pressure = 0.0;
  const double volume = enclosed_volume(ellipsoid.mesh.vertices, ellipsoid.mesh.faces);
  const NewtonReport report = ellipsoid.solver.solve_volume(x, pressure, volume, settings);
  if (volume_error) *volume_error = std::abs(enclosed_volume(unflatten(x), ellipsoid.mesh.faces) - volume) / volume;
  return report;
}

TEST(SlowAbandon, AStagnationWithinTheFactorIsConvergedAndSaysHowFarAboveTheTolerance) {
  const NewtonReport unbounded = solve_at_the_slack_boundary(1e12);
  ASSERT_TRUE(unbounded.converged) << unbounded.message;
  const double stagnated_at = unbounded.stagnated_at;
  ASSERT_GT(stagnated_at, 1.0) << "the case no longer stagnates: " << unbounded.message;

  double volume_error = 0.0;
  const NewtonReport within = solve_at_the_slack_boundary(2.0 * stagnated_at, &volume_error);
  EXPECT_TRUE(within.converged);
  EXPECT_EQ(within.stop, NewtonStop::Converged);
  EXPECT_NEAR(within.stagnated_at, stagnated_at, 1e-9 * stagnated_at);
  EXPECT_LE(volume_error, 1e-10);  // the volume is met to the tolerance itself
  EXPECT_NE(within.message.find("where Newton stagnated"), std::string::npos) << within.message;

  const NewtonReport beyond = solve_at_the_slack_boundary(0.5 * stagnated_at);
  EXPECT_FALSE(beyond.converged);
  EXPECT_EQ(beyond.stop, NewtonStop::Slow);
  EXPECT_EQ(beyond.stagnated_at, 0.0);
}

// The design's trials on the rising branch are never abandoned but still accept a stagnation within the
// factor; beyond it they run on to their iteration limit.
TEST(SlowAbandon, WithoutAbandoningAStagnationWithinTheFactorIsStillConverged) {
  const NewtonReport unbounded = solve_at_the_slack_boundary(1e12, nullptr, false);
  ASSERT_TRUE(unbounded.converged) << unbounded.message;
  const double stagnated_at = unbounded.stagnated_at;
  ASSERT_GT(stagnated_at, 1.0) << "the case no longer stagnates: " << unbounded.message;

  const NewtonReport within = solve_at_the_slack_boundary(2.0 * stagnated_at, nullptr, false);
  EXPECT_TRUE(within.converged);
  EXPECT_NEAR(within.stagnated_at, stagnated_at, 1e-9 * stagnated_at);

  const NewtonReport beyond = solve_at_the_slack_boundary(0.5 * stagnated_at, nullptr, false);
  EXPECT_FALSE(beyond.converged);
  EXPECT_NE(beyond.stop, NewtonStop::Slow);
  EXPECT_EQ(beyond.iterations, SLACK_BOUNDARY_ITERATIONS);
}

}  // namespace
}  // namespace balloon
