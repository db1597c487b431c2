// use_the_cpus_blas_kernels: on a CPU OpenBLAS 0.3.21 does not know, the factorizations run the kernels the
// CPU has (not Prescott's), and they solve as before.
#include "solve/blas_kernels.hpp"

#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <cstdlib>
#include <string>
#include <vector>

#include "solve/sparse_solver.hpp"

namespace balloon {
namespace {

/// The 5-point Laplacian of an n x n grid plus the identity (symmetric positive definite), as the upper
/// triangle in compressed columns: big enough for CHOLMOD's supernodes, so the dense kernels run.
struct GridMatrix {
  int n;
  std::vector<int> column_starts, row_indices;
  std::vector<double> values;
  Eigen::SparseMatrix<double> full;

  explicit GridMatrix(int side) : n(side * side), full(side * side, side * side) {
    std::vector<Eigen::Triplet<double>> entries;
    column_starts.push_back(0);
    for (int j = 0; j < n; ++j) {
      // Upper-triangle rows of column j in increasing order: the neighbour above, the left one, then j.
      for (int i : {j - side, j % side != 0 ? j - 1 : -1, j}) {
        if (i < 0) continue;
        const double value = i == j ? 5.0 : -1.0;
        row_indices.push_back(i);
        values.push_back(value);
        entries.emplace_back(i, j, value);
        if (i != j) entries.emplace_back(j, i, value);
      }
      column_starts.push_back(static_cast<int>(row_indices.size()));
    }
    full.setFromTriplets(entries.begin(), entries.end());
  }
};

TEST(BlasKernels, AFactorizationRunsTheKernelsTheCpuHasAndSolves) {
  SparseSolver solver;  // the first one in a process selects the kernels
  const GridMatrix matrix(70);
  solver.set_pattern(matrix.n, matrix.column_starts, matrix.row_indices);
  ASSERT_EQ(solver.factorize_llt(matrix.values), SparseSolver::Status::Ok);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.n, -1.0, 1.0);
  EXPECT_LT((matrix.full * solver.solve(rhs) - rhs).norm(), 1e-12 * rhs.norm());

  const std::string kernels = blas_kernel_name();
  if (kernels.empty()) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) GTEST_SKIP() << "OPENBLAS_CORETYPE chooses the kernels";
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    EXPECT_NE(kernels, "Prescott") << "a CPU with AVX2 runs SSE3 kernels";
  }
  EXPECT_EQ(std::getenv("OPENBLAS_CORETYPE"), nullptr) << "the environment is left as it was";
}

}  // namespace
}  // namespace balloon
