#include "solve/sparse_solver.hpp"

#include "solve/blas_kernels.hpp"
#include "solve/indefinite_factorization.hpp"
#include "solve/linear_algebra_threads.hpp"

#include <cholmod.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace balloon {

struct SparseSolver::Internals {
  cholmod_common common{};
  cholmod_sparse* matrix = nullptr;
  cholmod_factor* llt = nullptr;   // supernodal symbolic + numeric
  std::unique_ptr<IndefiniteFactorization> ldlt;  // symmetric indefinite matrices; made at first use
  enum class Factor { None, Llt, Ldlt };
  Factor last = Factor::None;  // the successful factorization solve() uses
  int n = 0;
  int negative = 0;

  Internals() {
    cholmod_start(&common);
    common.print = 0;
    common.error_handler = nullptr;
  }
  ~Internals() {
    if (llt) cholmod_free_factor(&llt, &common);
    if (matrix) cholmod_free_sparse(&matrix, &common);
    cholmod_finish(&common);
  }

  /// The values fit the pattern and are finite (neither factorization checks).
  void check_values(const std::vector<double>& values) const {
    if (values.size() != matrix->nzmax) throw std::invalid_argument("SparseSolver: value count does not match the pattern");
    for (double v : values)
      if (!std::isfinite(v)) throw std::invalid_argument("SparseSolver: non-finite matrix entry");
  }
  void copy_values(const std::vector<double>& values) {
    check_values(values);
    std::memcpy(matrix->x, values.data(), values.size() * sizeof(double));
  }
};

SparseSolver::SparseSolver() : m(std::make_unique<Internals>()) {
  use_the_cpus_blas_kernels();
  use_one_linear_algebra_thread();
}
SparseSolver::~SparseSolver() = default;

void SparseSolver::set_pattern(int n, const std::vector<int>& column_starts, const std::vector<int>& row_indices) {
  if (m->llt) cholmod_free_factor(&m->llt, &m->common);
  if (m->matrix) cholmod_free_sparse(&m->matrix, &m->common);
  m->last = Internals::Factor::None;
  m->ldlt.reset();
  m->n = n;
  m->matrix = cholmod_allocate_sparse(static_cast<size_t>(n), static_cast<size_t>(n), row_indices.size(), 1, 1, 1,
                                      CHOLMOD_REAL, &m->common);
  if (!m->matrix) throw std::runtime_error("SparseSolver: CHOLMOD could not allocate the matrix");
  std::memcpy(m->matrix->p, column_starts.data(), column_starts.size() * sizeof(int));
  std::memcpy(m->matrix->i, row_indices.data(), row_indices.size() * sizeof(int));
}

SparseSolver::Status SparseSolver::factorize_llt(const std::vector<double>& values, double shift) {
  m->copy_values(values);
  m->last = Internals::Factor::None;
  if (!m->llt) {
    m->common.supernodal = CHOLMOD_SUPERNODAL;
    m->common.final_ll = 1;
    m->llt = cholmod_analyze(m->matrix, &m->common);
    if (!m->llt) return Status::Failed;
  }
  m->common.supernodal = CHOLMOD_SUPERNODAL;
  m->common.final_ll = 1;
  m->common.quick_return_if_not_posdef = 1;
  double beta[2] = {shift, 0.0};
  ++m_factorizations;
  const int ok = cholmod_factorize_p(m->matrix, beta, nullptr, 0, m->llt, &m->common);
  m->negative = 0;
  if (!ok) return Status::Failed;
  if (m->common.status == CHOLMOD_NOT_POSDEF || m->llt->minor < m->llt->n) return Status::NotPositiveDefinite;
  m->last = Internals::Factor::Llt;
  return Status::Ok;
}

SparseSolver::Status SparseSolver::factorize_ldlt(const std::vector<double>& values, double shift) {
  m->check_values(values);
  m->last = Internals::Factor::None;
  m->negative = 0;
  if (!m->ldlt) {
    const auto* starts = static_cast<const int*>(m->matrix->p);
    const auto* rows = static_cast<const int*>(m->matrix->i);
    m->ldlt = std::make_unique<IndefiniteFactorization>();
    m->ldlt->set_pattern(m->n, std::vector<int>(starts, starts + m->n + 1),
                         std::vector<int>(rows, rows + m->matrix->nzmax));
  }
  ++m_factorizations;
  switch (m->ldlt->factorize(values, shift)) {
    case IndefiniteFactorization::Status::Ok: break;
    case IndefiniteFactorization::Status::Singular: return Status::Singular;
    case IndefiniteFactorization::Status::Failed: return Status::Failed;
  }
  m->negative = m->ldlt->negative_pivots();
  m->last = Internals::Factor::Ldlt;
  return Status::Ok;
}

int SparseSolver::negative_pivots() const { return m->negative; }

Eigen::VectorXd SparseSolver::solve(const Eigen::VectorXd& rhs) const { return solve_columns(rhs).col(0); }

Eigen::MatrixXd SparseSolver::solve_columns(const Eigen::MatrixXd& rhs) const {
  if (m->last == Internals::Factor::None) throw std::logic_error("SparseSolver::solve without a successful factorization");
  if (rhs.rows() != m->n) throw std::invalid_argument("SparseSolver::solve: size mismatch");
  if (!rhs.allFinite()) throw std::invalid_argument("SparseSolver::solve: non-finite right-hand side");
  if (m->last == Internals::Factor::Ldlt) return m->ldlt->solve_columns(rhs);
  cholmod_dense b{};
  b.nrow = static_cast<size_t>(m->n);
  b.ncol = static_cast<size_t>(rhs.cols());
  b.nzmax = b.nrow * b.ncol;
  b.d = static_cast<size_t>(m->n);
  b.x = const_cast<double*>(rhs.data());
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, m->llt, &b, &m->common);
  if (!x) throw std::runtime_error("SparseSolver::solve: CHOLMOD solve failed");
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), m->n, rhs.cols());
  cholmod_free_dense(&x, &m->common);
  return out;
}

}  // namespace balloon
