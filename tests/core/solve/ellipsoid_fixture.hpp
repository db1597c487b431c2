#pragma once
/// Test fixtures of the volume solver's tests: an ellipsoid with no symmetry a rigid mode could hide in,
/// and a silicone-like Mooney-Rivlin rubber.
#include "material/material.hpp"
#include "mesh/icosphere.hpp"

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

}  // namespace balloon::test
