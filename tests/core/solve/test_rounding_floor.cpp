// The convergence test's rounding floor (NewtonSettings): a residual tolerance finer than floating point
// can resolve ends as converged at the measured floor, and says so, instead of at the iteration limit;
// an ordinary tolerance never uses it.
#include <gtest/gtest.h>

#include <cmath>

#include "ellipsoid_fixture.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

struct Solved {
  NewtonReport report;
  double force_scale = 0.0;  ///< N, at the end
  double rounding = 0.0;     ///< N, the residual's measured rounding level at the end
};

/// Solves the ellipsoid to three times its volume, by volume or (at the pressure found) by pressure.
Solved solve(double relative_tolerance, bool by_pressure) {
  test::EllipsoidSolve ellipsoid;
  EquilibriumSolver& solver = ellipsoid.solver;
  const double target_volume = 3.0 * enclosed_volume(ellipsoid.mesh.vertices, ellipsoid.mesh.faces);
  NewtonSettings settings;
  settings.max_iterations = 60;
  Eigen::VectorXd x = flat(ellipsoid.mesh.vertices) * std::cbrt(3.0);
  double pressure = 0.0;
  Solved solved;
  solved.report = solver.solve_volume(x, pressure, target_volume, settings);
  settings.relative_tolerance = relative_tolerance;
  if (by_pressure) {
    solved.report = solver.solve_pressure(x, pressure, settings);
  } else {
    solved.report = solver.solve_volume(x, pressure, target_volume, settings);
  }
  solved.force_scale = solver.force_scale(x, pressure);
  const Eigen::VectorXd r = solver.assembly().restrict(solver.residual(x, pressure));
  solved.rounding = solver.residual_rounding(x, pressure, r);
  return solved;
}

TEST(RoundingFloor, AnOrdinaryToleranceNeverUsesIt) {
  const Solved solved = solve(1e-8, false);
  ASSERT_TRUE(solved.report.converged) << solved.report.message;
  EXPECT_EQ(solved.report.rounding_floor, 0.0);
  EXPECT_EQ(solved.report.message, "converged");
  // A well-shaped mesh evaluates its residual to near machine precision of the force scale.
  EXPECT_GT(solved.rounding, 0.0);
  EXPECT_LT(solved.rounding, 1e-12 * solved.force_scale);
}

TEST(RoundingFloor, ATolerancePastRoundingConvergesAtTheFloorAndSaysSo) {
  for (const bool by_pressure : {false, true}) {
    SCOPED_TRACE(by_pressure ? "pressure control" : "volume control");
    // 1e-20 of the force scale: far below the residual's rounding (about 1e-15 of it here).
    const Solved solved = solve(1e-20, by_pressure);
    ASSERT_TRUE(solved.report.converged) << solved.report.message;
    EXPECT_EQ(solved.report.stop, NewtonStop::Converged);
    EXPECT_GT(solved.report.rounding_floor, 0.0);
    EXPECT_LE(solved.report.residual_norm, solved.report.rounding_floor);
    EXPECT_LT(solved.report.rounding_floor, 1e-10 * solved.force_scale);
    EXPECT_LT(solved.report.iterations, 60);
    EXPECT_NE(solved.report.message.find("rounding floor"), std::string::npos) << solved.report.message;
  }
}

}  // namespace
}  // namespace balloon
