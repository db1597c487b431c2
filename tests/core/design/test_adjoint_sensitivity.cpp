#include "design/adjoint_sensitivity.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "material/material.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/inflation.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon {
namespace {

Eigen::VectorXd flat(const Positions& p) {
  Eigen::VectorXd out(3 * p.rows());
  for (Eigen::Index v = 0; v < p.rows(); ++v) out.segment<3>(3 * v) = p.row(v).transpose();
  return out;
}

Positions unflat(const Eigen::VectorXd& x) {
  Positions out(x.size() / 3, 3);
  for (Eigen::Index v = 0; v < out.rows(); ++v) out.row(v) = x.segment<3>(3 * v).transpose();
  return out;
}

/// An asymmetric balloon (42-vertex ellipsoid, semi-axes 14, 10, 8 mm) inflated 3-fold under volume
/// control, with the model and solver the design uses, for finite differences of x(rest).
struct Scene {
  TriMesh rest;
  Material material = *parse_material_spec("silicone");
  fem::BalloonModel model;
  std::vector<bool> fixed;
  EquilibriumSolver solver;
  Eigen::VectorXd x;
  double pressure_mpa = 0.0;
  double target_volume = 0.0;
  NewtonSettings tight;

  static TriMesh ellipsoid() {
    TriMesh mesh = make_icosphere(10.0, 1);
    mesh.vertices.col(0) *= 1.4;
    mesh.vertices.col(2) *= 0.8;
    return mesh;
  }
  static std::vector<bool> support(const TriMesh& mesh) {
    std::vector<bool> fixed(static_cast<size_t>(3 * mesh.vertex_count()), false);
    for (int c : rigid_support_coordinates(mesh.vertices)) fixed[static_cast<size_t>(c)] = true;
    return fixed;
  }

  Scene()
      : rest(ellipsoid()),
        model(rest, material, std::vector<double>(static_cast<size_t>(rest.face_count()), 0.5)),
        fixed(support(rest)),
        solver(model, fixed) {
    InflationOptions inflation;
    inflation.material = material;
    inflation.volume_ratio = 3.0;
    const InflationResult inflated = inflate(rest, inflation);
    EXPECT_TRUE(inflated.converged) << inflated.message;
    x = flat(inflated.deformed);
    pressure_mpa = 1e-3 * inflated.pressure_kpa;
    target_volume = enclosed_volume(inflated.deformed, rest.faces);
    tight.relative_tolerance = 1e-12;
    tight.max_iterations = 50;
    // inflate() used its own support: settle on this solver's pinned coordinates.
    const NewtonReport report = solver.solve_volume(x, pressure_mpa, target_volume, tight);
    EXPECT_TRUE(report.converged) << report.message;
  }

  /// The equilibrium of rest shape `rest_x` (flat), from the base equilibrium.
  Eigen::VectorXd equilibrium(const Eigen::VectorXd& rest_x, double* pressure = nullptr) {
    model.set_rest_positions(unflat(rest_x));
    Eigen::VectorXd solved = x;
    double p = pressure_mpa;
    const NewtonReport report = solver.solve_volume(solved, p, target_volume, tight);
    EXPECT_TRUE(report.converged) << report.message;
    if (pressure) *pressure = p;
    return solved;
  }

  /// A smooth random direction over the free rest coordinates (mm per unit step).
  Eigen::VectorXd direction(unsigned seed) const {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    Eigen::VectorXd d(3 * rest.vertex_count());
    for (Eigen::Index c = 0; c < d.size(); ++c) d[c] = fixed[static_cast<size_t>(c)] ? 0.0 : uniform(random);
    return d;
  }
};

TEST(AdjointSensitivity, DesignGradientMatchesCentralDifferences) {
  Scene scene;
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

TEST(AdjointSensitivity, LinearResponseMatchesCentralDifferences) {
  Scene scene;
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

}  // namespace
}  // namespace balloon
