// TriangleAssembly's vertex-group pattern, as the augmented Lagrangian uses it: one group per vertex
// (its one-ring) over a doubled vertex set (rest and inflated copies), filled with dense blocks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <stdexcept>

#include "design_test_meshes.hpp"
#include "fem/assembly.hpp"

namespace {

using balloon::TriMesh;
using balloon::fem::TriangleAssembly;

std::vector<std::vector<int>> one_rings(const TriMesh& mesh) {
  std::vector<std::vector<int>> rings(static_cast<size_t>(mesh.vertex_count()));
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) rings[static_cast<size_t>(mesh.faces(f, k))].push_back(mesh.faces(f, j));
  for (auto& ring : rings) {
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  }
  return rings;
}

TEST(TriangleAssemblyGroups, TrianglesAsGroupsGiveTheTrianglePattern) {
  const TriMesh mesh = balloon::design_test::make_icosphere(2);
  std::vector<bool> fixed(static_cast<size_t>(3 * mesh.vertex_count()), false);
  fixed[0] = fixed[4] = fixed[17] = true;
  std::vector<std::vector<int>> triangles;
  for (int f = 0; f < mesh.face_count(); ++f) triangles.push_back({mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)});
  const TriangleAssembly by_face(mesh.faces, mesh.vertex_count(), fixed);
  const TriangleAssembly by_group(triangles, mesh.vertex_count(), fixed);
  EXPECT_EQ(by_face.free_count(), by_group.free_count());
  EXPECT_EQ(by_face.column_starts(), by_group.column_starts());
  EXPECT_EQ(by_face.row_indices(), by_group.row_indices());
}

TEST(TriangleAssemblyGroups, OneRingBlocksOverRestAndInflatedCopiesMatchADenseSum) {
  const TriMesh mesh = balloon::design_test::make_icosphere(1);
  const int vertices = mesh.vertex_count();
  const int n = 3 * vertices;  // coordinates of one copy
  std::vector<bool> fixed(static_cast<size_t>(2 * n), false);
  for (int c : {1, 5, n + 2, n + 9, n + 10}) fixed[static_cast<size_t>(c)] = true;
  const auto rings = one_rings(mesh);
  std::vector<std::vector<int>> groups;
  for (const auto& ring : rings) {
    std::vector<int> group = ring;
    for (int u : ring) group.push_back(vertices + u);
    groups.push_back(group);
  }
  TriangleAssembly assembly(groups, 2 * vertices, fixed);

  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  for (const auto& group : groups) {
    std::vector<int> coordinates;
    for (int u : group)
      for (int a = 0; a < 3; ++a) coordinates.push_back(3 * u + a);
    Eigen::MatrixXd jacobian(3, static_cast<Eigen::Index>(coordinates.size()));
    for (Eigen::Index i = 0; i < jacobian.size(); ++i) jacobian.data()[i] = uniform(random);
    const Eigen::MatrixXd block = jacobian.transpose() * jacobian;
    assembly.add_block(coordinates, block);
    for (size_t i = 0; i < coordinates.size(); ++i)
      for (size_t j = 0; j < coordinates.size(); ++j)
        dense(coordinates[i], coordinates[j]) += block(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
  }
  // Entry by entry, both halves listed: only the upper one is stored, so the sum counts it once.
  assembly.add_entry(3, n + 3, 0.5);
  assembly.add_entry(n + 3, 3, 0.5);
  dense(3, n + 3) += 0.5;
  dense(n + 3, 3) += 0.5;

  Eigen::VectorXd v(2 * n);
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = fixed[static_cast<size_t>(i)] ? 0.0 : uniform(random);
  Eigen::VectorXd expected = dense * v;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (fixed[static_cast<size_t>(i)]) expected[i] = 0.0;
  const Eigen::VectorXd product = assembly.extend(assembly.multiply(assembly.restrict(v)));
  EXPECT_LT((product - expected).norm(), 1e-12 * expected.norm());

  // Two vertices two rings apart share a one-ring; three apart do not.
  int far = -1;
  for (int u = 0; u < vertices && far < 0; ++u) {
    bool shares = false;
    for (const auto& ring : rings)
      if (std::binary_search(ring.begin(), ring.end(), 0) && std::binary_search(ring.begin(), ring.end(), u)) shares = true;
    if (!shares) far = u;
  }
  ASSERT_GE(far, 0);
  EXPECT_THROW(assembly.add_entry(3 * 0, 3 * far, 1.0), std::out_of_range);
}

}  // namespace
