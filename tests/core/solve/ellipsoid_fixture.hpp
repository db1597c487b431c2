#pragma once
/// Test fixtures of the volume solver's tests: an ellipsoid with no symmetry a rigid mode could hide in,
/// and a silicone-like Mooney-Rivlin rubber.
#include <vector>

#include "fem/balloon_model.hpp"
#include "material/material.hpp"
#include "mesh/icosphere.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon::test {

/// A 642-vertex ellipsoid (semi-axes 16, 10, 8 mm).
inline TriMesh ellipsoid() {
  TriMesh mesh = make_icosphere(10.0, 3);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    mesh.vertices(v, 0) *= 1.6;
    mesh.vertices(v, 2) *= 0.8;
  }
  return mesh;
}

/// Mooney-Rivlin, C1 = 0.18 MPa, C2 = 0.02 MPa.
inline Material silicone() {
  Material material;
  material.model = MaterialModel::MooneyRivlin;
  material.params = {0.18, 0.02, 0.0};
  return material;
}

/// The ellipsoid in silicone 0.5 mm thick, and a volume solver holding its six rigid-support coordinates.
struct EllipsoidSolve {
  static std::vector<bool> support_of(const TriMesh& mesh) {
    std::vector<bool> support(static_cast<size_t>(3 * mesh.vertex_count()), false);
    for (int c : rigid_support_coordinates(mesh.vertices)) support[static_cast<size_t>(c)] = true;
    return support;
  }

  TriMesh mesh = ellipsoid();
  fem::BalloonModel model{mesh, silicone(), std::vector<double>(static_cast<size_t>(mesh.face_count()), 0.5)};
  EquilibriumSolver solver{model, support_of(mesh)};
};

}  // namespace balloon::test
