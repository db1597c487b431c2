#include "solve/indefinite_factorization.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <random>
#include <thread>
#include <vector>

#include "solve/sparse_solver.hpp"

namespace balloon {
namespace {

/// A random symmetric band matrix (bandwidth 3) with `negative` negative eigenvalues, dense for the
/// reference and as the upper triangle in compressed columns for the factorization.
struct BandedMatrix {
  Eigen::MatrixXd dense;
  std::vector<int> column_starts, row_indices;
  std::vector<double> values;

  BandedMatrix(int n, int negative, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    Eigen::MatrixXd band = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < std::min(n, i + 4); ++j) band(i, j) = band(j, i) = 0.3 * uniform(random);
    // Diagonal entries of magnitude >= 2.5 against off-diagonal row sums <= 1.8 (Gershgorin): `negative` of
    // them negative, spread over the matrix, fix the inertia.
    const int spacing = negative > 0 ? n / negative : n;
    for (int i = 0; i < n; ++i) {
      const bool flipped = i % spacing == 0 && i / spacing < negative;
      band(i, i) = (flipped ? -1.0 : 1.0) * (3.0 + 0.5 * uniform(random));
    }
    dense = band;
    column_starts.push_back(0);
    for (int j = 0; j < n; ++j) {
      for (int i = std::max(0, j - 3); i <= j; ++i) {
        row_indices.push_back(i);
        values.push_back(dense(i, j));
      }
      column_starts.push_back(static_cast<int>(row_indices.size()));
    }
  }
  int negative_eigenvalues(double shift = 0.0) const {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(dense + shift * Eigen::MatrixXd::Identity(dense.rows(), dense.cols()));
    return static_cast<int>((eigen.eigenvalues().array() < 0.0).count());
  }
};

TEST(IndefiniteFactorization, InertiaAndSolveMatchTheDenseReference) {
  for (int negative : {0, 1, 3, 7}) {
    const BandedMatrix matrix(60, negative, 10u + static_cast<unsigned>(negative));
    ASSERT_EQ(matrix.negative_eigenvalues(), negative) << "the test matrix has the inertia it was built for";
    IndefiniteFactorization factorization;
    factorization.set_pattern(60, matrix.column_starts, matrix.row_indices);
    ASSERT_EQ(factorization.factorize(matrix.values), IndefiniteFactorization::Status::Ok);
    EXPECT_EQ(factorization.negative_pivots(), negative);
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(60, -1.0, 2.0);
    const Eigen::VectorXd solution = factorization.solve(rhs);
    EXPECT_LT((matrix.dense * solution - rhs).norm(), 1e-12 * rhs.norm()) << negative << " negative";
  }
}

TEST(IndefiniteFactorization, SeveralColumnsSolveAsEachAloneWithEitherFactorization) {
  // The Newton steps solve K^-1 r and K^-1 v in one pass; each column must be what its own solve gives,
  // with the supernodal LL^T (positive definite) and with MUMPS's LDL^T (indefinite).
  for (int negative : {0, 3}) {
    const BandedMatrix matrix(60, negative, 40u + static_cast<unsigned>(negative));
    SparseSolver solver;
    solver.set_pattern(60, matrix.column_starts, matrix.row_indices);
    if (negative == 0) {
      ASSERT_EQ(solver.factorize_llt(matrix.values), SparseSolver::Status::Ok);
    } else {
      ASSERT_EQ(solver.factorize_ldlt(matrix.values), SparseSolver::Status::Ok);
      ASSERT_EQ(solver.negative_pivots(), negative);
    }
    Eigen::MatrixXd rhs(60, 3);
    rhs << Eigen::VectorXd::LinSpaced(60, -1.0, 2.0), Eigen::VectorXd::Ones(60), Eigen::VectorXd::LinSpaced(60, 3.0, 0.0);
    const Eigen::MatrixXd together = solver.solve_columns(rhs);
    ASSERT_EQ(together.cols(), 3);
    for (int k = 0; k < 3; ++k) {
      const Eigen::VectorXd alone = solver.solve(rhs.col(k));
      EXPECT_LT((together.col(k) - alone).norm(), 1e-13 * alone.norm()) << negative << " negative, column " << k;
      EXPECT_LT((matrix.dense * together.col(k) - rhs.col(k)).norm(), 1e-12 * rhs.col(k).norm());
    }
  }
}

TEST(IndefiniteFactorization, OneFactorizationServesManyMatricesAndPatternsInItsOwnWorkspace) {
  // The factorization keeps MUMPS's workspace from one call to the next (and the factors live in it until
  // the next call): matrices of one pattern one after another, then a larger pattern, then the first
  // again. Near-zero diagonals force 2x2 and delayed pivots, which need more room than estimated.
  IndefiniteFactorization factorization;
  for (int n : {60, 240, 60}) {
    for (int round = 0; round < 6; ++round) {
      const int negative = (round * 5) % 11;
      BandedMatrix matrix(n, negative, 100u * static_cast<unsigned>(n) + static_cast<unsigned>(round));
      if (round % 2 == 1) {
        for (int j = 0; j < n; j += 3) {
          matrix.dense(j, j) = 1e-9;
          matrix.values[static_cast<size_t>(matrix.column_starts[static_cast<size_t>(j) + 1] - 1)] = 1e-9;
        }
      }
      if (round == 0) factorization.set_pattern(n, matrix.column_starts, matrix.row_indices);
      ASSERT_EQ(factorization.factorize(matrix.values), IndefiniteFactorization::Status::Ok) << n << ", " << round;
      EXPECT_EQ(factorization.negative_pivots(), matrix.negative_eigenvalues()) << n << ", " << round;
      const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
      const Eigen::VectorXd solution = factorization.solve(rhs);
      EXPECT_LT((matrix.dense * solution - rhs).norm(), 1e-9 * rhs.norm()) << n << ", " << round;
    }
  }
}

TEST(IndefiniteFactorization, AFactorizationBeyondWhatMallocRecyclesSolvesAgainAndAgain) {
  // The pattern of a surface's stiffness with its bending hinges: a grid of side x side nodes, 3 unknowns
  // each, every node coupled to its 8 neighbours. MUMPS's workspace is then beyond 32 MiB, so it is ours
  // and kept from one factorization to the next. Diagonals of magnitude 10 against off-diagonal row sums
  // below 7.8 (Gershgorin) fix the inertia: every fifth diagonal entry negative, then every third.
  const int side = 110, n = 3 * side * side;
  std::vector<int> column_starts{0}, row_indices;
  for (int j = 0; j < n; ++j) {
    const int node = j / 3, x = node % side, y = node / side;
    std::vector<int> rows;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (x + dx < 0 || x + dx >= side || y + dy < 0 || y + dy >= side) continue;
        const int neighbour = (y + dy) * side + x + dx;
        for (int c = 0; c < 3; ++c)
          if (3 * neighbour + c <= j) rows.push_back(3 * neighbour + c);
      }
    std::sort(rows.begin(), rows.end());
    row_indices.insert(row_indices.end(), rows.begin(), rows.end());
    column_starts.push_back(static_cast<int>(row_indices.size()));
  }
  IndefiniteFactorization factorization;
  factorization.set_pattern(n, column_starts, row_indices);
  std::mt19937 random(7u);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  for (int every : {5, 3, 5}) {
    std::vector<double> values(row_indices.size());
    std::vector<Eigen::Triplet<double>> entries;
    int negative = 0;
    for (int j = 0; j < n; ++j) {
      for (int k = column_starts[static_cast<size_t>(j)]; k < column_starts[static_cast<size_t>(j) + 1]; ++k) {
        const int i = row_indices[static_cast<size_t>(k)];
        const bool flipped = i == j && j % every == 0;
        values[static_cast<size_t>(k)] = i == j ? (flipped ? -10.0 : 10.0) : uniform(random);
        negative += flipped ? 1 : 0;
        entries.emplace_back(i, j, values[static_cast<size_t>(k)]);
      }
    }
    Eigen::SparseMatrix<double> upper(n, n);
    upper.setFromTriplets(entries.begin(), entries.end());
    ASSERT_EQ(factorization.factorize(values), IndefiniteFactorization::Status::Ok) << every;
    EXPECT_EQ(factorization.negative_pivots(), negative) << every;
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    const Eigen::VectorXd solution = factorization.solve(rhs);
    const Eigen::VectorXd product = upper.selfadjointView<Eigen::Upper>() * solution;
    EXPECT_LT((product - rhs).norm(), 1e-10 * rhs.norm()) << every;
  }
}

TEST(IndefiniteFactorization, ShiftMovesTheInertiaAndSingularIsReported) {
  const BandedMatrix matrix(40, 4, 3u);
  IndefiniteFactorization factorization;
  factorization.set_pattern(40, matrix.column_starts, matrix.row_indices);
  // A shift of 10 exceeds every |diagonal| plus Gershgorin radius: positive definite.
  ASSERT_EQ(factorization.factorize(matrix.values, 10.0), IndefiniteFactorization::Status::Ok);
  EXPECT_EQ(factorization.negative_pivots(), matrix.negative_eigenvalues(10.0));
  EXPECT_EQ(factorization.negative_pivots(), 0);
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(40);
  const Eigen::VectorXd solution = factorization.solve(rhs);
  EXPECT_LT(((matrix.dense + 10.0 * Eigen::MatrixXd::Identity(40, 40)) * solution - rhs).norm(), 1e-12);

  std::vector<double> zero(matrix.values.size(), 0.0);
  EXPECT_EQ(factorization.factorize(zero), IndefiniteFactorization::Status::Singular);
  EXPECT_THROW((void)factorization.solve(rhs), std::logic_error) << "no solve after a failed factorization";
}

TEST(IndefiniteFactorization, SolversOnSeveralThreadsAgree) {
  // The server factorizes on several worker threads at once.
  const BandedMatrix matrix(200, 5, 7u);
  std::vector<int> inertia(4, -1);
  std::vector<double> residual(4, 1.0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      SparseSolver solver;
      solver.set_pattern(200, matrix.column_starts, matrix.row_indices);
      for (int repeat = 0; repeat < 20; ++repeat) {
        if (solver.factorize_ldlt(matrix.values) != SparseSolver::Status::Ok) return;
        inertia[static_cast<size_t>(t)] = solver.negative_pivots();
        const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(200);
        residual[static_cast<size_t>(t)] = (matrix.dense * solver.solve(rhs) - rhs).norm();
      }
    });
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < 4; ++t) {
    EXPECT_EQ(inertia[static_cast<size_t>(t)], 5) << "thread " << t;
    EXPECT_LT(residual[static_cast<size_t>(t)], 1e-10) << "thread " << t;
  }
}

}  // namespace
}  // namespace balloon
