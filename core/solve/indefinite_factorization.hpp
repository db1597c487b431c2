#pragma once
/// Multifrontal LDL^T (with 1x1 and 2x2 pivots) of a sparse symmetric indefinite matrix, with MUMPS hidden
/// behind this interface. It replaces CHOLMOD's simplicial LDL^T, which has no supernodes: on the
/// stiffness of a sphere past its pressure maximum it took 3-10x the time of one supernodal LL^T, while
/// the multifrontal factorization (dense fronts, BLAS-3) costs about the same as the LL^T (README,
/// "Performance"). Analyse the pattern once, then factorize new values as often as needed.
#include <Eigen/Core>
#include <memory>
#include <vector>

namespace balloon {

class IndefiniteFactorization {
 public:
  enum class Status { Ok, Singular, Failed };

  IndefiniteFactorization();
  ~IndefiniteFactorization();
  IndefiniteFactorization(const IndefiniteFactorization&) = delete;
  IndefiniteFactorization& operator=(const IndefiniteFactorization&) = delete;

  /// Sets the pattern: upper triangle (row <= column), compressed columns, n x n (0-based indices).
  void set_pattern(int n, const std::vector<int>& column_starts, const std::vector<int>& row_indices);

  /// LDL^T of A + shift I, `values` in the pattern's order (finite; the caller checks). The symbolic
  /// analysis (fill-reducing ordering) is done at the first call and reused.
  Status factorize(const std::vector<double>& values, double shift = 0.0);
  /// Negative eigenvalues of the last factorized matrix (Sylvester's inertia from D's pivots).
  int negative_pivots() const { return m_negative; }
  /// Solves with the last successful factorization.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;
  /// The same for each column of `rhs`, in one pass over the factors.
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& rhs) const;

 private:
  struct Internals;
  std::unique_ptr<Internals> m;
  int m_negative = 0;
};

}  // namespace balloon
