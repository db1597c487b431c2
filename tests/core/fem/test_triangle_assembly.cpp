// TriangleAssembly's triangle-and-hinge pattern against a dense reference: random symmetric element blocks,
// scattered through the precomputed slots, equal their dense sum over the free coordinates (fixed ones
// dropped), and the pattern holds exactly the coupled pairs, upper triangle, rows sorted.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <set>
#include <utility>

#include "fem/assembly.hpp"
#include "fem/hinge_bending.hpp"
#include "mesh/icosphere.hpp"

namespace balloon::fem {
namespace {

template <int N>
Eigen::Matrix<double, N, N> random_symmetric(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix<double, N, N> block;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) block(i, j) = u(rng);
  return block + block.transpose();
}

/// Adds a block over the coordinates of `vertices` into a dense 3#V matrix.
template <int N>
void add_dense(Eigen::MatrixXd& dense, const int* vertices, const Eigen::Matrix<double, N, N>& block) {
  for (int k = 0; k < N; ++k)
    for (int l = 0; l < N; ++l) dense(3 * vertices[l / 3] + l % 3, 3 * vertices[k / 3] + k % 3) += block(l, k);
}

TEST(TriangleAssembly, ScatteredTriangleAndHingeBlocksEqualTheirDenseSumWithFixedCoordinates) {
  const TriMesh mesh = make_icosphere(1.0, 1);
  const int coordinates = 3 * mesh.vertex_count();
  // Whole vertices and single coordinates fixed, as the clamped rim and the rigid support fix them.
  std::vector<bool> fixed(static_cast<size_t>(coordinates), false);
  for (int c : {0, 1, 2, 7, 14, 15, 23, 31, 32}) fixed[static_cast<size_t>(c)] = true;
  const std::vector<HingeVertices> hinges = mesh_hinges(mesh.faces);
  TriangleAssembly assembly(mesh.faces, mesh.vertex_count(), fixed, hinges);

  std::mt19937 rng(5);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(coordinates, coordinates);
  assembly.set_zero();
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Matrix9d block = random_symmetric<9>(rng);
    assembly.add(f, block);
    add_dense<9>(dense, &mesh.faces(f, 0), block);
  }
  for (size_t h = 0; h < hinges.size(); ++h) {
    const Matrix12d block = random_symmetric<12>(rng);
    assembly.add_hinge(static_cast<int>(h), block);
    add_dense<12>(dense, hinges[h].data(), block);
  }

  // The assembled upper triangle, mirrored, against the dense sum restricted to the free coordinates.
  const int n = assembly.free_count();
  Eigen::MatrixXd assembled = Eigen::MatrixXd::Zero(n, n);
  std::set<std::pair<int, int>> stored;
  for (int col = 0; col < n; ++col) {
    for (int p = assembly.column_starts()[static_cast<size_t>(col)]; p < assembly.column_starts()[static_cast<size_t>(col) + 1]; ++p) {
      const int row = assembly.row_indices()[static_cast<size_t>(p)];
      ASSERT_LE(row, col) << "upper triangle only";
      if (p > assembly.column_starts()[static_cast<size_t>(col)]) {
        ASSERT_LT(assembly.row_indices()[static_cast<size_t>(p) - 1], row) << "rows sorted and unique";
      }
      stored.insert({row, col});
      assembled(row, col) = assembled(col, row) = assembly.values()[static_cast<size_t>(p)];
    }
  }
  Eigen::MatrixXd reference(n, n);
  int coupled_pairs = 0;
  for (int a = 0; a < coordinates; ++a)
    for (int b = 0; b < coordinates; ++b) {
      const int row = assembly.free_index(a), col = assembly.free_index(b);
      if (row < 0 || col < 0) continue;
      reference(row, col) = dense(a, b);
      if (row <= col && dense(a, b) != 0.0) {
        ++coupled_pairs;
        EXPECT_TRUE(stored.count({row, col})) << "coupled pair (" << row << ", " << col << ") not in the pattern";
      }
    }
  EXPECT_EQ(n, coordinates - 9);
  EXPECT_GT(coupled_pairs, n);
  EXPECT_LT((assembled - reference).norm(), 1e-12 * reference.norm());
}

}  // namespace
}  // namespace balloon::fem
