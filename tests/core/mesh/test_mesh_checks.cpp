#include "mesh/mesh_checks.hpp"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/mesh/mesh_test_helpers.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// Validates a copy, expects a failure whose message contains every given fragment, and checks that
/// a failed validation leaves the mesh untouched.
void expect_rejected(const TriMesh& broken, std::initializer_list<std::string> fragments) {
  TriMesh mesh = broken;
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_FALSE(report.ok()) << "accepted a broken mesh";
  for (const auto& fragment : fragments) {
    EXPECT_NE(report.error().find(fragment), std::string::npos)
        << "message '" << report.error() << "' lacks '" << fragment << "'";
  }
  EXPECT_EQ(report.error().find('\n'), std::string::npos) << "message spans lines";
  // Bitwise, so that NaN coordinates compare equal to themselves.
  ASSERT_EQ(mesh.vertices.size(), broken.vertices.size());
  EXPECT_EQ(std::memcmp(mesh.vertices.data(), broken.vertices.data(),
                        sizeof(double) * static_cast<std::size_t>(broken.vertices.size())),
            0);
  EXPECT_EQ(mesh.faces, broken.faces);
}

/// Two meshes side by side as one (indices of the second shifted).
TriMesh concatenate(const TriMesh& a, const TriMesh& b) {
  TriMesh both;
  both.vertices.resize(a.vertex_count() + b.vertex_count(), 3);
  both.vertices << a.vertices, b.vertices;
  both.faces.resize(a.face_count() + b.face_count(), 3);
  both.faces << a.faces, (b.faces.array() + a.vertex_count()).matrix();
  return both;
}

TEST(MeshChecks, AcceptsAClosedOutwardMeshUnchanged) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  TriMesh mesh = sphere;
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_FALSE(report->flipped);
  EXPECT_EQ(report->removed_unreferenced_vertices, 0);
  EXPECT_TRUE(report->notes.empty());
  EXPECT_EQ(report->vertices, 162);
  EXPECT_EQ(report->faces, 320);
  EXPECT_EQ(report->edges, 480);
  EXPECT_EQ(report->genus, 0);
  EXPECT_NEAR(report->volume_mm3, enclosed_volume(sphere.vertices, sphere.faces), 1e-9);
  EXPECT_NEAR(report->bounding_box_diagonal_mm, 20.0 * std::sqrt(3.0), 0.5);
  EXPECT_EQ(mesh.vertices, sphere.vertices);
  EXPECT_EQ(mesh.faces, sphere.faces);
}

TEST(MeshChecks, FlipsAnInwardMesh) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  TriMesh mesh = sphere;
  mesh.faces.col(1).swap(mesh.faces.col(2));
  ASSERT_LT(enclosed_volume(mesh.vertices, mesh.faces), 0.0);
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_TRUE(report->flipped);
  ASSERT_EQ(report->notes.size(), 1u);
  EXPECT_NE(report->notes[0].find("reversed"), std::string::npos);
  const double volume = enclosed_volume(mesh.vertices, mesh.faces);
  EXPECT_GT(volume, 0.0);
  EXPECT_NEAR(volume, enclosed_volume(sphere.vertices, sphere.faces), 1e-9);
  EXPECT_NEAR(report->volume_mm3, volume, 1e-9);
}

TEST(MeshChecks, RemovesUnreferencedVertices) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  TriMesh mesh;
  // Stray vertices at the front, in the middle (shifting indices) and far away at the end.
  mesh.vertices.resize(sphere.vertex_count() + 3, 3);
  mesh.vertices << Eigen::RowVector3d(1, 2, 3), sphere.vertices.topRows(20), Eigen::RowVector3d(4, 5, 6),
      sphere.vertices.bottomRows(sphere.vertex_count() - 20), Eigen::RowVector3d(1e6, 0, 0);
  mesh.faces = sphere.faces;
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) mesh.faces(f, k) += mesh.faces(f, k) < 20 ? 1 : 2;
  }
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_EQ(report->removed_unreferenced_vertices, 3);
  EXPECT_EQ(report->vertices, sphere.vertex_count());
  EXPECT_FALSE(report->flipped);
  EXPECT_EQ(mesh.vertices, sphere.vertices);
  EXPECT_EQ(mesh.faces, sphere.faces);
  EXPECT_LT(report->bounding_box_diagonal_mm, 40.0);  // the far stray vertex does not count
}

TEST(MeshChecks, RejectsEmptyMeshes) {
  expect_rejected(TriMesh{}, {"empty"});
  TriMesh only_vertices = make_icosphere(1.0, 0);
  only_vertices.faces.resize(0, 3);
  expect_rejected(only_vertices, {"empty", "no faces"});
}

TEST(MeshChecks, RejectsNonFiniteCoordinates) {
  TriMesh mesh = make_icosphere(10.0, 1);
  mesh.vertices(5, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(mesh, {"non-finite", "vertex 5"});
  mesh.vertices(5, 1) = 0.0;
  mesh.vertices(7, 2) = INFINITY;
  expect_rejected(mesh, {"non-finite", "vertex 7"});
}

TEST(MeshChecks, RejectsFaceIndexOutOfRange) {
  TriMesh mesh = make_icosphere(10.0, 1);
  mesh.faces(3, 1) = 9999;
  expect_rejected(mesh, {"face 3", "vertex 9999", "out of range"});
  mesh.faces(3, 1) = -1;
  expect_rejected(mesh, {"face 3", "vertex -1", "out of range"});
}

TEST(MeshChecks, RejectsRepeatedVertexInAFace) {
  TriMesh mesh = make_icosphere(10.0, 1);
  mesh.faces(7, 2) = mesh.faces(7, 0);
  expect_rejected(mesh, {"degenerate face 7", "vertex " + std::to_string(mesh.faces(7, 0))});
}

TEST(MeshChecks, RejectsZeroAreaTriangles) {
  TriMesh mesh = make_icosphere(10.0, 1);
  // Put the third corner of face 11 on the midpoint of its first edge: collinear, zero area. Other
  // faces around that vertex stay non-degenerate on a sphere.
  const int a = mesh.faces(11, 0), b = mesh.faces(11, 1), c = mesh.faces(11, 2);
  mesh.vertices.row(c) = 0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b));
  expect_rejected(mesh, {"zero-area", "face 11"});
}

TEST(MeshChecks, AcceptsSliversAboveTheZeroAreaThreshold) {
  // hand_fist.off has a 0.69 degree sliver; a thin but real triangle is not zero-area.
  TriMesh mesh = make_icosphere(10.0, 1);
  const int a = mesh.faces(11, 0), b = mesh.faces(11, 1), c = mesh.faces(11, 2);
  const Eigen::RowVector3d mid = 0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b));
  mesh.vertices.row(c) = mid + 1e-3 * (mesh.vertices.row(c) - mid);
  const auto report = validate_balloon_mesh(mesh);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_LT(report->min_angle_deg, 0.1);
}

TEST(MeshChecks, RejectsNonManifoldEdges) {
  TriMesh sphere = make_icosphere(10.0, 1);
  TriMesh mesh;
  mesh.vertices = sphere.vertices;
  mesh.faces.resize(sphere.face_count() + 1, 3);
  // A fin: a third face on edge (f0[0], f0[1]).
  const int a = sphere.faces(0, 0), b = sphere.faces(0, 1);
  mesh.faces << sphere.faces, b, a, sphere.faces(40, 0);
  std::string edge = "(";  // appended: GCC 12 warns falsely (-Wrestrict) on "(" + std::string
  edge += std::to_string(a) + ", " + std::to_string(b) + ")";
  expect_rejected(mesh, {"non-manifold edge", edge, "shared by 3 faces", "80"});
}

TEST(MeshChecks, AFaceBombGetsAShortMessage) {
  // 4 vertices and 300k copies of one face: the message named every face (2.3 MB); now the first few.
  TriMesh mesh;
  mesh.vertices = make_icosphere(10.0, 0).vertices.topRows(4);
  mesh.faces.resize(300000, 3);
  for (int f = 0; f < mesh.face_count(); ++f) mesh.faces.row(f) << 0, 1, 2;
  expect_rejected(mesh, {"non-manifold edge", "shared by 300000 faces", "faces 0, 1, 2, 3 and 299996 more"});
  EXPECT_LT(validate_balloon_mesh(mesh).error().size(), 200u);
}

TEST(MeshChecks, RejectsOpenBoundary) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  TriMesh mesh = sphere;
  mesh.faces = sphere.faces.bottomRows(sphere.face_count() - 1);  // drop face 0
  expect_rejected(mesh, {"open boundary", "edge (", "of face", "only one face"});
  // The hole is bounded by edges of three faces; the message names the lowest of them.
  TriMesh mesh2 = mesh;
  const auto report = validate_balloon_mesh(mesh2);
  ASSERT_FALSE(report.ok());
  int lowest = mesh.face_count();
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int p = mesh.faces(f, k), q = mesh.faces(f, (k + 1) % 3);
      for (int j = 0; j < 3; ++j) {
        const int s = sphere.faces(0, j), t = sphere.faces(0, (j + 1) % 3);
        if (p == t && q == s) lowest = std::min(lowest, f);
      }
    }
  }
  EXPECT_NE(report.error().find("of face " + std::to_string(lowest) + " "), std::string::npos)
      << report.error();
}

TEST(MeshChecks, RejectsNonManifoldVertex) {
  // Two spheres touching at one vertex: every edge has two faces, but the vertex has two fans.
  const TriMesh a = make_icosphere(10.0, 1);
  TriMesh b = make_icosphere(10.0, 1);
  const int touching_a = 0;  // (-1, phi, 0) direction
  const int touching_b = 3;  // (1, -phi, 0): antipodal, so the spheres touch and do not overlap
  b.vertices.rowwise() += a.vertices.row(touching_a) - b.vertices.row(touching_b);
  TriMesh both = concatenate(a, b);
  for (int f = a.face_count(); f < both.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (both.faces(f, k) == a.vertex_count() + touching_b) both.faces(f, k) = touching_a;
    }
  }
  expect_rejected(both, {"non-manifold vertex " + std::to_string(touching_a), "2 separate fans"});
}

/// A double cone: apex 0 above, apex 1 below, `slices` rim vertices; each apex has `slices` triangles.
TriMesh double_cone(int slices) {
  TriMesh mesh;
  mesh.vertices.resize(slices + 2, 3);
  mesh.vertices.row(0) << 0.0, 0.0, 50.0;
  mesh.vertices.row(1) << 0.0, 0.0, -50.0;
  for (int i = 0; i < slices; ++i) {
    const double angle = 2.0 * M_PI * i / slices;
    mesh.vertices.row(i + 2) << 50.0 * std::cos(angle), 50.0 * std::sin(angle), 0.0;
  }
  mesh.faces.resize(2 * slices, 3);
  for (int i = 0; i < slices; ++i) {
    const int a = i + 2, b = (i + 1) % slices + 2;
    mesh.faces.row(2 * i) << 0, a, b;
    mesh.faces.row(2 * i + 1) << 1, b, a;
  }
  return mesh;
}

TEST(MeshChecks, AVertexMayHaveAtMostTheDegreeLimitOfTriangles) {
  TriMesh widest = double_cone(MAX_VERTEX_DEGREE);
  const auto report = validate_balloon_mesh(widest);
  ASSERT_TRUE(report.ok()) << report.error();
  EXPECT_EQ(report->genus, 0);
  expect_rejected(double_cone(MAX_VERTEX_DEGREE + 1),
                  {"vertex 0 has " + std::to_string(MAX_VERTEX_DEGREE + 1) + " triangles", "remesh"});
}

TEST(MeshChecks, RejectsSeveralComponents) {
  const TriMesh a = make_icosphere(10.0, 1);
  TriMesh b = make_icosphere(5.0, 1);
  b.vertices.rowwise() += Eigen::RowVector3d(50.0, 0.0, 0.0);
  expect_rejected(concatenate(a, b), {"several connected components", "has 2", "faces 0 and 80"});
}

TEST(MeshChecks, RejectsInconsistentOrientation) {
  TriMesh mesh = make_icosphere(10.0, 1);
  std::swap(mesh.faces(30, 1), mesh.faces(30, 2));
  expect_rejected(mesh, {"inconsistent orientation", "30", "same direction"});
}

TEST(MeshChecks, RejectsZeroVolume) {
  // Two triangles back to back: closed and manifold, but it encloses nothing.
  TriMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 0, 2, 1;
  expect_rejected(mesh, {"zero volume"});
}

}  // namespace
}  // namespace balloon
