#include "mesh/mesh_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "core/mesh/mesh_test_helpers.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon {
namespace {

using test::unit_cube;

TEST(MeshGeometry, UnitCubeMeasures) {
  const TriMesh cube = unit_cube();
  EXPECT_NEAR(enclosed_volume(cube.vertices, cube.faces), 1.0, 1e-15);
  EXPECT_NEAR(surface_area(cube.vertices, cube.faces), 6.0, 1e-14);
  EXPECT_NEAR(bounding_box_diagonal(cube.vertices), std::sqrt(3.0), 1e-15);
  EXPECT_TRUE(centroid(cube.vertices).isApprox(Eigen::RowVector3d(0.5, 0.5, 0.5), 1e-15));
  EXPECT_NEAR(min_angle_deg(cube.vertices, cube.faces), 45.0, 1e-12);
}

TEST(MeshGeometry, ScaleToDiagonalScalesAboutTheOriginOrLeavesNoExtentAlone) {
  TriMesh cube = unit_cube();
  EXPECT_NEAR(scale_to_diagonal(cube.vertices, 100.0), 100.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(bounding_box_diagonal(cube.vertices), 100.0, 1e-12);
  EXPECT_NEAR(enclosed_volume(cube.vertices, cube.faces), std::pow(100.0 / std::sqrt(3.0), 3), 1e-6);
  EXPECT_TRUE(cube.vertices.row(0).isZero()) << "the corner at the origin stays there";
  Positions point = Positions::Constant(3, 3, 2.0);
  EXPECT_EQ(scale_to_diagonal(point, 100.0), 0.0);
  EXPECT_TRUE((point.array() == 2.0).all());
  Positions none(0, 3);
  EXPECT_EQ(scale_to_diagonal(none, 100.0), 0.0);
}

TEST(MeshGeometry, VolumeIsSignedAndTranslationInvariant) {
  TriMesh cube = unit_cube();
  cube.vertices.rowwise() += Eigen::RowVector3d(100.0, -50.0, 3.0);
  EXPECT_NEAR(enclosed_volume(cube.vertices, cube.faces), 1.0, 1e-9);
  cube.faces.col(1).swap(cube.faces.col(2));
  EXPECT_NEAR(enclosed_volume(cube.vertices, cube.faces), -1.0, 1e-9);
  EXPECT_NEAR(surface_area(cube.vertices, cube.faces), 6.0, 1e-12);
}

TEST(MeshGeometry, EmptyInputs) {
  const Positions none(0, 3);
  EXPECT_EQ(bounding_box_diagonal(none), 0.0);
  EXPECT_TRUE(centroid(none).isZero());
  EXPECT_EQ(min_angle_deg(none, Faces(0, 3)), 180.0);
  EXPECT_EQ(enclosed_volume(none, Faces(0, 3)), 0.0);
}

TEST(MeshGeometry, MinAngleOfSampleMeshesMatchesProvenance) {
  // Minimum angles (degrees) stated in tests/data/meshes/PROVENANCE.md, rounded there.
  const std::pair<const char*, double> expected[] = {
      {"hand_fist.off", 0.69}, {"cube_866.off", 45.0}, {"retinal_bumpy_blob.off", 1.13},
      {"icosphere_812.off", 54.1}, {"spot.obj", 10.2}, {"stanford_bunny_1839.obj", 13.2}};
  for (const auto& [name, angle] : expected) {
    const auto mesh = read_mesh(test::sample_mesh(name));
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    EXPECT_NEAR(min_angle_deg(mesh->vertices, mesh->faces), angle, 0.01 + 0.005 * angle) << name;
  }
}

TEST(MeshGeometry, MinAngleIsTheSmallestCornerAngleOnEveryCorpusMesh) {
  // min_angle_deg takes the corner opposite each face's shortest edge; every corner's angle, including the
  // anchor's 0.001-degree slivers, must give the same minimum.
  for (const auto& entry : std::filesystem::directory_iterator(test::sample_mesh(""))) {
    const std::string extension = entry.path().extension().string();
    if (extension != ".off" && extension != ".obj") continue;
    const auto mesh = read_mesh(entry.path().string());
    ASSERT_TRUE(mesh.ok()) << mesh.error();
    double every_corner = 180.0;
    for (Eigen::Index f = 0; f < mesh->faces.rows(); ++f)
      for (const double angle : corner_angles_deg(mesh->vertices, mesh->faces.row(f).transpose()))
        every_corner = std::min(every_corner, angle);
    EXPECT_NEAR(min_angle_deg(mesh->vertices, mesh->faces), every_corner, 1e-12 * (1.0 + every_corner))
        << entry.path().filename();
  }
}

TEST(MeshEdgeTopology, ClosedIcosphereHasTwoFacesPerEdge) {
  const TriMesh mesh = make_icosphere(5.0, 3);
  const EdgeTopology topology = build_edge_topology(mesh.faces, mesh.vertex_count());
  const auto edge_count = topology.edges.rows();
  ASSERT_EQ(edge_count * 2, mesh.face_count() * 3);  // E = 3F/2
  EXPECT_EQ(mesh.vertex_count() - edge_count + mesh.face_count(), 2);  // Euler, genus 0
  for (Eigen::Index e = 0; e < edge_count; ++e) {
    const int a = topology.edges(e, 0), b = topology.edges(e, 1);
    for (int k = 0; k < 2; ++k) {
      const int f = topology.edge_faces(e, k);
      ASSERT_GE(f, 0) << "edge " << e << " lacks a face";
      // Face 0 runs a -> b, face 1 runs b -> a (consistent orientation); the opposite vertex closes it.
      const int from = k == 0 ? a : b, to = k == 0 ? b : a;
      const int opposite = topology.edge_opposite(e, k);
      bool found = false;
      for (int c = 0; c < 3; ++c) {
        found |= mesh.faces(f, c) == from && mesh.faces(f, (c + 1) % 3) == to &&
                 mesh.faces(f, (c + 2) % 3) == opposite;
      }
      ASSERT_TRUE(found) << "edge " << e << " side " << k;
    }
    EXPECT_NE(topology.edge_faces(e, 0), topology.edge_faces(e, 1));
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int e = topology.face_edges(f, k);
      const int p = mesh.faces(f, (k + 1) % 3), q = mesh.faces(f, (k + 2) % 3);
      ASSERT_EQ(std::minmax(p, q), std::minmax(topology.edges(e, 0), topology.edges(e, 1)));
    }
  }
}

TEST(MeshEdgeTopology, OpenMeshHasBoundaryEdges) {
  TriMesh mesh = make_icosphere(5.0, 1);
  const Faces all = mesh.faces;
  mesh.faces = all.bottomRows(all.rows() - 1);  // remove face 0: a triangular hole
  const EdgeTopology topology = build_edge_topology(mesh.faces, mesh.vertex_count());
  int boundary = 0;
  for (Eigen::Index e = 0; e < topology.edges.rows(); ++e) {
    if (topology.edge_faces(e, 1) < 0) {
      ++boundary;
      EXPECT_EQ(topology.edge_opposite(e, 1), -1);
      EXPECT_GE(topology.edge_faces(e, 0), 0);
    }
  }
  EXPECT_EQ(boundary, 3);
  EXPECT_EQ(topology.edges.rows(), 120);  // edges are not lost with the face
}

TEST(MeshEdgeTopology, RejectsNonManifoldEdgesAndBadIndices) {
  TriMesh mesh = make_icosphere(5.0, 1);
  Faces more(mesh.face_count() + 1, 3);
  more << mesh.faces, mesh.faces(0, 0), mesh.faces(0, 1), mesh.faces(5, 2);
  EXPECT_THROW(build_edge_topology(more, mesh.vertex_count()), std::invalid_argument);
  EXPECT_THROW(build_edge_topology(mesh.faces, mesh.vertex_count() - 1), std::invalid_argument);
}

TEST(MeshGeometry, AMeshFarFromTheOriginEnclosesTheVolumeItDoesAtTheOrigin) {
  const TriMesh sphere = make_icosphere(20.0, 3);
  const double at_origin = enclosed_volume(sphere.vertices, sphere.faces);
  for (double offset : {1e5, 1e7, 1e9}) {
    const Positions far = sphere.vertices.rowwise() + Eigen::RowVector3d(offset, -offset, offset);
    // Tetrahedra on the origin summed products near offset^3 (1e27 mm^3 at 1e9) to a volume of 3.3e4.
    EXPECT_NEAR(enclosed_volume(far, sphere.faces), at_origin, 1e-12 * offset / 20.0 * at_origin) << offset;
  }
}

}  // namespace
}  // namespace balloon
