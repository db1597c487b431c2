#include "solve/indefinite_factorization.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
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
