#pragma once
/// Limited-memory BFGS model of the inverse Hessian (two-loop recursion), with a fixed sparse
/// preconditioner as its initial inverse Hessian, scaled by the newest pair's curvature.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <deque>
#include <memory>
#include <utility>

namespace balloon {

class Lbfgs {
 public:
  /// Keeps the newest `memory` (s, y) pairs.
  explicit Lbfgs(int memory = 30);
  ~Lbfgs();
  Lbfgs(const Lbfgs&) = delete;
  Lbfgs& operator=(const Lbfgs&) = delete;

  /// Factorizes `hessian` plus a shift of 1e-3 of its mean diagonal as the initial inverse Hessian; none
  /// (the identity) when that fails.
  void set_preconditioner(Eigen::SparseMatrix<double> hessian);
  /// The model's inverse Hessian times `gradient`.
  Eigen::VectorXd apply(const Eigen::VectorXd& gradient) const;
  /// Adds the pair (step, gradient change) when its curvature is positive (s^T y > 1e-12 |s| |y|).
  void update(const Eigen::VectorXd& step, const Eigen::VectorXd& change);
  /// Forgets every pair (a stale curvature model).
  void clear() { m_pairs.clear(); }
  bool empty() const { return m_pairs.empty(); }
  /// The initial inverse Hessian (the preconditioner) alone times `q`; `q` itself without one.
  Eigen::VectorXd precondition(const Eigen::VectorXd& q) const;

 private:
  struct Preconditioner;
  int m_memory;
  std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>> m_pairs;  ///< (s, y)
  std::unique_ptr<Preconditioner> m_preconditioner;
};

}  // namespace balloon
