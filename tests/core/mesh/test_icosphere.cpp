#include "mesh/icosphere.hpp"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

TEST(Icosphere, VertexAndFaceCountsPerSubdivision) {
  const int expected_vertices[] = {12, 42, 162, 642, 2562, 10242, 40962};
  for (int k = 0; k <= 6; ++k) {
    const TriMesh mesh = make_icosphere(1.0, k);
    EXPECT_EQ(mesh.vertex_count(), expected_vertices[k]) << "subdivisions " << k;
    EXPECT_EQ(mesh.face_count(), 20 * (1 << (2 * k))) << "subdivisions " << k;
  }
}

TEST(Icosphere, EveryVertexLiesOnTheSphere) {
  const double radius = 7.5;
  const TriMesh mesh = make_icosphere(radius, 3);
  const Eigen::VectorXd distances = mesh.vertices.rowwise().norm();
  EXPECT_LT((distances.array() - radius).abs().maxCoeff(), 1e-12 * radius);
}

TEST(Icosphere, FacesAreCounterClockwiseSeenFromOutside) {
  const TriMesh mesh = make_icosphere(3.0, 3);
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Eigen::RowVector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::RowVector3d b = mesh.vertices.row(mesh.faces(f, 1));
    const Eigen::RowVector3d c = mesh.vertices.row(mesh.faces(f, 2));
    const Eigen::RowVector3d normal = (b - a).cross(c - a);
    ASSERT_GT(normal.dot(a + b + c), 0.0) << "face " << f << " points inwards";
  }
}

TEST(Icosphere, VolumeAndAreaApproachTheSphere) {
  const double radius = 10.0;
  const TriMesh mesh = make_icosphere(radius, 4);
  const double sphere_volume = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
  const double sphere_area = 4.0 * std::numbers::pi * radius * radius;
  const double volume = enclosed_volume(mesh.vertices, mesh.faces);
  const double area = surface_area(mesh.vertices, mesh.faces);
  // Inscribed polyhedron: slightly smaller than the sphere, by about 0.3% at 2562 vertices.
  EXPECT_LT(volume, sphere_volume);
  EXPECT_NEAR(volume / sphere_volume, 1.0, 0.01);
  EXPECT_LT(area, sphere_area);
  EXPECT_NEAR(area / sphere_area, 1.0, 0.01);
  RecordProperty("volume_relative_error", std::to_string(volume / sphere_volume - 1.0));
}

TEST(Icosphere, IsAValidBalloonMesh) {
  TriMesh mesh = make_icosphere(10.0, 2);
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_FALSE(report->flipped);
  EXPECT_EQ(report->genus, 0);
  EXPECT_EQ(report->vertices, 162);
  EXPECT_EQ(report->edges, 480);
  EXPECT_GT(report->min_angle_deg, 50.0);  // near-equilateral triangles
}

TEST(Icosphere, RejectsBadArguments) {
  EXPECT_THROW(make_icosphere(1.0, -1), std::invalid_argument);
  EXPECT_THROW(make_icosphere(1.0, 8), std::invalid_argument);
  EXPECT_THROW(make_icosphere(0.0, 2), std::invalid_argument);
  EXPECT_THROW(make_icosphere(-1.0, 2), std::invalid_argument);
  EXPECT_THROW(make_icosphere(std::nan(""), 2), std::invalid_argument);
  EXPECT_NO_THROW(make_icosphere(1.0, 0));
}

}  // namespace
}  // namespace balloon
