#pragma once
/// Sparse symmetric solver for the Newton systems, with CHOLMOD (positive definite) and MUMPS (indefinite,
/// solve/indefinite_factorization) hidden behind this interface.
/// Analyse the pattern once, then factorize new values as often as needed: the symbolic analysis
/// (ordering, supernodes) is reused.
#include <Eigen/Core>
#include <memory>
#include <vector>

namespace balloon {

class SparseSolver {
 public:
  enum class Status { Ok, NotPositiveDefinite, Singular, Failed };

  SparseSolver();
  ~SparseSolver();
  SparseSolver(const SparseSolver&) = delete;
  SparseSolver& operator=(const SparseSolver&) = delete;

  /// Sets the pattern: upper triangle (row <= column), compressed columns, n x n.
  /// The arrays must stay alive and unchanged while this solver is used.
  void set_pattern(int n, const std::vector<int>& column_starts, const std::vector<int>& row_indices);

  /// Supernodal LL^T of A + shift I. NotPositiveDefinite when it does not exist.
  Status factorize_llt(const std::vector<double>& values, double shift = 0.0);
  /// Multifrontal LDL^T (MUMPS) of A + shift I, for symmetric indefinite matrices; see negative_pivots().
  Status factorize_ldlt(const std::vector<double>& values, double shift = 0.0);
  /// Number of negative entries of D after factorize_ldlt (the inertia of A); 0 after an LL^T.
  int negative_pivots() const;

  /// Solves with the last factorization. Non-finite right-hand sides are rejected.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;
  /// The same for each column of `rhs`. One pass over the factors serves every column: a solve with one
  /// right-hand side costs the memory traffic of reading the whole factor, so two columns at once cost
  /// little more than one.
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& rhs) const;

  /// Number of numeric factorizations done so far.
  int factorizations() const { return m_factorizations; }

 private:
  struct Internals;
  std::unique_ptr<Internals> m;
  int m_factorizations = 0;
};

}  // namespace balloon
