#pragma once
/// Meshes for the core/design tests: icospheres, bumpy spheres, the sample data in tests/data/meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"
#include "mesh/tri_mesh.hpp"
#include "solve/inflation.hpp"

namespace balloon::design_test {

/// Icosphere of the given radius (mm) after `level` subdivisions (10 * 4^level + 2 vertices).
inline TriMesh make_icosphere(int level, double radius = 1.0) { return balloon::make_icosphere(radius, level); }

/// Icosphere with a smooth radial bump pattern r = radius * (1 + amplitude * sin(3x) sin(2y) cos(4z)).
inline TriMesh make_bumpy_sphere(int level, double radius, double amplitude) {
  TriMesh mesh = balloon::make_icosphere(1.0, level);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const Eigen::Vector3d p = mesh.vertices.row(i);
    const double r = radius * (1.0 + amplitude * std::sin(3 * p.x()) * std::sin(2 * p.y()) * std::cos(4 * p.z()));
    mesh.vertices.row(i) = r * p;
  }
  return mesh;
}

/// A sample mesh from tests/data/meshes; fails the calling test if it cannot be read.
inline TriMesh read_sample_mesh(const std::string& name) {
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/" + name);
  EXPECT_TRUE(mesh.ok()) << mesh.error();
  return mesh.ok() ? *mesh : TriMesh{};
}

/// A target with a known answer (paper Fig. 5): an ellipsoid (semi-axes 32, 20 and 20 * z_scale mm;
/// an icosphere after `level` subdivisions, 642 vertices at 3) inflated six-fold with silicone by volume
/// control; fails the calling test if it does not inflate.
inline TriMesh inflated_ellipsoid_target(int level = 3, double z_scale = 0.8) {
  TriMesh rest = balloon::make_icosphere(20.0, level);
  for (int v = 0; v < rest.vertex_count(); ++v) {
    rest.vertices(v, 0) *= 1.6;
    rest.vertices(v, 2) *= z_scale;
  }
  InflationOptions inflation;
  inflation.material = *parse_material_spec("silicone");
  inflation.volume_ratio = 6.0;
  const InflationResult inflated = inflate(rest, inflation);
  EXPECT_TRUE(inflated.converged) << inflated.message;
  TriMesh target = rest;
  target.vertices = inflated.deformed;
  return target;
}

}  // namespace balloon::design_test
