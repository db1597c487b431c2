#pragma once
/// The design's sensitivity scene for finite-difference tests: an asymmetric balloon (42-vertex ellipsoid,
/// semi-axes 14, 10, 8 mm) inflated 3-fold under volume control, with the model and solver the design
/// uses, and equilibria of perturbed rest shapes solved tightly from it; optionally with bending on.
#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "fem/balloon_model.hpp"
#include "material/material.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/inflation.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon::design_test {

inline Eigen::VectorXd flat(const Positions& p) {
  Eigen::VectorXd out(3 * p.rows());
  for (Eigen::Index v = 0; v < p.rows(); ++v) out.segment<3>(3 * v) = p.row(v).transpose();
  return out;
}

inline Positions unflat(const Eigen::VectorXd& x) {
  Positions out(x.size() / 3, 3);
  for (Eigen::Index v = 0; v < out.rows(); ++v) out.row(v) = x.segment<3>(3 * v).transpose();
  return out;
}

struct Scene {
  TriMesh rest;
  Material material;
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

  static fem::BalloonModel make_model(const TriMesh& rest, const Material& material, double thickness_mm,
                                      bool bending) {
    fem::BalloonModel model(rest, material, std::vector<double>(static_cast<size_t>(rest.face_count()), thickness_mm));
    model.set_bending(bending);
    return model;
  }

  /// `rest` of `material`, `thickness_mm` thick, inflated `volume_ratio`-fold and settled tightly on this
  /// scene's solver; `bending`: the sheet's bending hinges on.
  Scene(TriMesh rest_mesh, const Material& rubber, double thickness_mm, double volume_ratio, bool bending)
      : rest(std::move(rest_mesh)),
        material(rubber),
        model(make_model(rest, material, thickness_mm, bending)),
        fixed(support(rest)),
        solver(model, fixed) {
    InflationOptions inflation;
    inflation.material = material;
    inflation.thickness_mm = thickness_mm;
    inflation.bending = bending ? BendingUse::On : BendingUse::Off;
    inflation.volume_ratio = volume_ratio;
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

  /// The silicone ellipsoid inflated 3-fold; with `bending` a thick sheet, so that the hinges matter.
  explicit Scene(bool bending = false)
      : Scene(ellipsoid(), *parse_material_spec("silicone"), bending ? 2.0 : 0.5, 3.0, bending) {}

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

}  // namespace balloon::design_test
