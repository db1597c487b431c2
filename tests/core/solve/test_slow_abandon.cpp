// NewtonSettings::abandon_slow: a volume solve that converges quadratically is left alone, and one that
// creeps stops early with NewtonStop::Slow instead of running to its iteration limit.
#include <gtest/gtest.h>

#include <cmath>

#include "ellipsoid_fixture.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// Solves the ellipsoid to `ratio` times its volume from `start_scale` times its rest shape.
NewtonReport solve(double ratio, double start_scale, bool abandon_slow) {
  test::EllipsoidSolve ellipsoid;
  NewtonSettings settings;
  settings.relative_tolerance = 1e-8;
  settings.max_iterations = 200;
  settings.abandon_slow = abandon_slow;
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

}  // namespace
}  // namespace balloon
