#pragma once
// Shared by the tests of core/mesh: sample paths, temporary folders, mesh fixtures, geometry comparison.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include <unistd.h>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon::test {

/// Path of a sample mesh in tests/data/meshes.
inline std::string sample_mesh(const std::string& name) {
  return std::string(BALLOON_TEST_DATA_DIR) + "/meshes/" + name;
}

/// A fresh folder under the system temp dir, removed with everything in it at scope exit.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    static std::atomic<int> counter{0};
    m_path = std::filesystem::temp_directory_path() /
             ("balloon-mesh-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::create_directories(m_path);
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  std::string file(const std::string& name) const { return (m_path / name).string(); }
  const std::filesystem::path& path() const { return m_path; }
  int entry_count() const {
    int n = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(m_path)) ++n;
    return n;
  }

 private:
  std::filesystem::path m_path;
};

/// An icosphere moved off the origin and rotated so that coordinates have many digits.
inline TriMesh offset_icosphere(int subdivisions = 2) {
  TriMesh mesh = make_icosphere(25.0, subdivisions);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  mesh.vertices = (mesh.vertices * rotation.transpose()).rowwise() + Eigen::RowVector3d(12.5, -7.25, 3.0);
  return mesh;
}

/// The unit cube [0,1]^3 as 12 outward triangles.
inline TriMesh unit_cube() {
  TriMesh cube;
  cube.vertices.resize(8, 3);
  cube.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  cube.faces.resize(12, 3);
  cube.faces << 0, 2, 1, 0, 3, 2,  // z = 0, normal -z
      4, 5, 6, 4, 6, 7,            // z = 1
      0, 1, 5, 0, 5, 4,            // y = 0
      2, 3, 7, 2, 7, 6,            // y = 1
      1, 2, 6, 1, 6, 5,            // x = 1
      0, 4, 7, 0, 7, 3;            // x = 0
  return cube;
}

/// An icosphere (radius mm) with one cap sliver of smallest angle `angle_deg`: its face (a, b, c) is split
/// at m, inside the face at tan(angle) |ab| / 2 from the midpoint of ab, into (a, m, c), (m, b, c) and
/// the cap (a, b, m), which is the last face.
inline TriMesh sphere_with_cap_sliver(double radius, int subdivisions, double angle_deg) {
  TriMesh mesh = make_icosphere(radius, subdivisions);
  const int a = mesh.faces(0, 0), b = mesh.faces(0, 1), c = mesh.faces(0, 2);
  const Eigen::RowVector3d pa = mesh.vertices.row(a), pb = mesh.vertices.row(b), pc = mesh.vertices.row(c);
  const Eigen::RowVector3d mid = 0.5 * (pa + pb);
  const double offset = std::tan(angle_deg * M_PI / 180.0) * 0.5 * (pb - pa).norm();
  const int m = mesh.vertex_count();
  mesh.vertices.conservativeResize(m + 1, 3);
  mesh.vertices.row(m) = mid + offset * (pc - mid).normalized();
  const int f = mesh.face_count();
  mesh.faces.conservativeResize(f + 2, 3);
  mesh.faces.row(0) << a, m, c;
  mesh.faces.row(f) << m, b, c;
  mesh.faces.row(f + 1) << a, b, m;
  return mesh;
}

/// An icosphere (radius mm) with two needle slivers of smallest angle about `angle_deg`: a vertex m on the
/// edge ab of its first face, at tan(angle) |ac| from a, splits both faces of that edge; (a, m, c) and
/// its neighbour across am are the needles (a short edge, two long ones).
inline TriMesh sphere_with_needle_slivers(double radius, int subdivisions, double angle_deg) {
  TriMesh mesh = make_icosphere(radius, subdivisions);
  const int a = mesh.faces(0, 0), b = mesh.faces(0, 1), c = mesh.faces(0, 2);
  int across = -1, o = -1;
  for (int f = 1; f < mesh.face_count() && across < 0; ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.faces(f, k) == b && mesh.faces(f, (k + 1) % 3) == a) across = f, o = mesh.faces(f, (k + 2) % 3);
  const Eigen::RowVector3d pa = mesh.vertices.row(a), pb = mesh.vertices.row(b), pc = mesh.vertices.row(c);
  const int m = mesh.vertex_count();
  mesh.vertices.conservativeResize(m + 1, 3);
  mesh.vertices.row(m) = pa + std::tan(angle_deg * M_PI / 180.0) * (pc - pa).norm() * (pb - pa).normalized();
  const int f = mesh.face_count();
  mesh.faces.conservativeResize(f + 2, 3);
  mesh.faces.row(0) << a, m, c;
  mesh.faces.row(f) << m, b, c;
  mesh.faces.row(across) << b, m, o;
  mesh.faces.row(f + 1) << m, a, o;
  return mesh;
}

/// True if `actual` is `expected` up to vertex renumbering: every vertex has a partner within
/// relative_tolerance * bounding-box diagonal and the faces map onto the same oriented triangles.
/// Brute force: for small meshes only.
inline ::testing::AssertionResult same_geometry(const TriMesh& expected, const TriMesh& actual,
                                              double relative_tolerance) {
  if (expected.vertex_count() != actual.vertex_count() || expected.face_count() != actual.face_count()) {
    return ::testing::AssertionFailure() << "counts differ: expected " << expected.vertex_count() << " / "
                                       << expected.face_count() << ", got " << actual.vertex_count()
                                       << " / " << actual.face_count();
  }
  const double tolerance = relative_tolerance * bounding_box_diagonal(expected.vertices);
  std::vector<int> partner(static_cast<std::size_t>(expected.vertex_count()));
  double worst = 0.0;
  for (int i = 0; i < expected.vertex_count(); ++i) {
    int best = -1;
    double best_distance = INFINITY;
    for (int j = 0; j < actual.vertex_count(); ++j) {
      const double d = (expected.vertices.row(i) - actual.vertices.row(j)).norm();
      if (d < best_distance) best_distance = d, best = j;
    }
    if (!(best_distance <= tolerance)) {
      return ::testing::AssertionFailure() << "vertex " << i << " has no partner within " << tolerance
                                         << " (nearest " << best_distance << ")";
    }
    worst = std::max(worst, best_distance);
    partner[static_cast<std::size_t>(i)] = best;
  }
  // Oriented triangles in a canonical rotation (smallest index first).
  auto canonical = [](int a, int b, int c) {
    if (a <= b && a <= c) return std::array{a, b, c};
    if (b <= a && b <= c) return std::array{b, c, a};
    return std::array{c, a, b};
  };
  std::set<std::array<int, 3>> actual_faces;
  for (int f = 0; f < actual.face_count(); ++f) {
    actual_faces.insert(canonical(actual.faces(f, 0), actual.faces(f, 1), actual.faces(f, 2)));
  }
  for (int f = 0; f < expected.face_count(); ++f) {
    const auto mapped = canonical(partner[static_cast<std::size_t>(expected.faces(f, 0))],
                                  partner[static_cast<std::size_t>(expected.faces(f, 1))],
                                  partner[static_cast<std::size_t>(expected.faces(f, 2))]);
    if (!actual_faces.count(mapped)) return ::testing::AssertionFailure() << "face " << f << " is missing";
  }
  return ::testing::AssertionSuccess() << "largest vertex distance " << worst;
}

}  // namespace balloon::test
