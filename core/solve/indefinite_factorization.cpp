#include "solve/indefinite_factorization.hpp"

#include <dmumps_c.h>

#include <algorithm>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

namespace balloon {
namespace {

/// MUMPS's "use the default communicator" value; the sequential library ignores MPI altogether.
constexpr int MUMPS_COMM_WORLD = -987654;
constexpr int JOB_INIT = -1, JOB_END = -2, JOB_ANALYSE = 1, JOB_FACTORIZE = 2, JOB_SOLVE = 3;
/// INFO(1) values: the workspace estimated at analysis was too small (delayed 2x2 pivots need more).
constexpr int WORKSPACE_TOO_SMALL = -9, INTEGER_WORKSPACE_TOO_SMALL = -8, MEMORY_TOO_SMALL = -17;
constexpr int NUMERICALLY_SINGULAR = -10;
/// glibc's malloc serves blocks up to 32 MiB (its largest dynamic mmap threshold) from memory it recycles;
/// larger ones are mapped afresh at each allocation (mallopt(3)).
constexpr double GLIBC_LARGEST_RECYCLED_BLOCK = 32.0 * 1024 * 1024;

/// Every MUMPS call goes through this lock. The sequential MUMPS of Debian 12 (5.5, with the PORD
/// ordering and its MPI stub library) does not document that separate instances may run concurrently,
/// and the server factorizes on several worker threads; the indefinite path is rare enough that
/// serializing it costs little.
std::mutex& mumps_lock() {
  static std::mutex lock;
  return lock;
}

}  // namespace

struct IndefiniteFactorization::Internals {
  DMUMPS_STRUC_C mumps{};
  std::vector<int> rows, columns;  // 1-based coordinates of the stored entries (MUMPS's convention)
  std::vector<double> values;      // the matrix handed to MUMPS, shift included
  std::vector<int> diagonal_slots;  // index in `values` of each diagonal entry
  // MUMPS's real workspace (its array S: the fronts, then the factors) when it is larger than glibc
  // recycles: ours, so that it outlives one factorization. Left to MUMPS, S is then mapped afresh at each
  // one, and the page faults and zeroing of its tens of MB took a quarter of the time of a bent
  // 8,000-vertex balloon's solve (S 59 MB). Below that size ours was no faster (S 15 MB: 0-5% slower).
  std::vector<double> workspace;
  bool analysed = false;
  bool factorized = false;
  int n = 0;

  Internals() {
    std::lock_guard<std::mutex> guard(mumps_lock());
    mumps.job = JOB_INIT;
    mumps.par = 1;  // the host takes part in the factorization (there is only the host)
    mumps.sym = 2;  // general symmetric: LDL^T with 2x2 pivots
    mumps.comm_fortran = MUMPS_COMM_WORLD;
    dmumps_c(&mumps);
    if (mumps.infog[0] < 0) throw std::runtime_error("IndefiniteFactorization: MUMPS could not start");
    mumps.icntl[0] = -1;  // no error, diagnostic or global messages on any stream
    mumps.icntl[1] = -1;
    mumps.icntl[2] = -1;
    mumps.icntl[3] = 0;
    // PORD: on the 3#V stiffness patterns of surface meshes it gave the fastest factorization of the
    // orderings this build has (10k-vertex sphere: 180 ms against 470 ms with SCOTCH and AMF).
    mumps.icntl[6] = 4;
    // ICNTL(8) = 1: scale by the diagonal (congruent, so the inertia is unchanged). MUMPS's default for a
    // symmetric matrix, an iterative row and column scaling, was 5% of a creeping path's time (dino, 20 mm,
    // silicone x8); the full robustness bench took 3.5% less time on the 567 cases whose Newton steps
    // stayed the same.
    mumps.icntl[7] = 1;
  }
  ~Internals() {
    std::lock_guard<std::mutex> guard(mumps_lock());
    mumps.job = JOB_END;
    dmumps_c(&mumps);
  }

  void call(int job) {
    mumps.job = job;
    dmumps_c(&mumps);
  }

  /// Hands MUMPS a workspace of at least `entries`; beyond what LWK_USER's int counts (16 GB), none: MUMPS
  /// then allocates its own.
  void use_workspace(size_t entries) {
    workspace = std::vector<double>();  // the old one first: never both at once
    mumps.wk_user = nullptr;
    mumps.lwk_user = 0;
    if (entries > static_cast<size_t>(std::numeric_limits<int>::max())) return;
    workspace.resize(entries);
    mumps.wk_user = workspace.data();
    mumps.lwk_user = static_cast<int>(entries);
  }
};

IndefiniteFactorization::IndefiniteFactorization() : m(std::make_unique<Internals>()) {}
IndefiniteFactorization::~IndefiniteFactorization() = default;

void IndefiniteFactorization::set_pattern(int n, const std::vector<int>& column_starts,
                                          const std::vector<int>& row_indices) {
  if (n < 0 || column_starts.size() != static_cast<size_t>(n) + 1)
    throw std::invalid_argument("IndefiniteFactorization: malformed pattern");
  m->n = n;
  m->rows.clear();
  m->columns.clear();
  m->diagonal_slots.assign(static_cast<size_t>(n), -1);
  for (int column = 0; column < n; ++column) {
    for (int k = column_starts[static_cast<size_t>(column)]; k < column_starts[static_cast<size_t>(column) + 1]; ++k) {
      const int row = row_indices[static_cast<size_t>(k)];
      if (row == column) m->diagonal_slots[static_cast<size_t>(column)] = static_cast<int>(m->rows.size());
      m->rows.push_back(row + 1);
      m->columns.push_back(column + 1);
    }
  }
  m->values.assign(m->rows.size(), 0.0);
  m->analysed = false;
  m->factorized = false;
}

IndefiniteFactorization::Status IndefiniteFactorization::factorize(const std::vector<double>& values, double shift) {
  if (values.size() != m->values.size())
    throw std::invalid_argument("IndefiniteFactorization: value count does not match the pattern");
  m->factorized = false;
  m_negative = 0;
  if (m->n == 0) {
    m->factorized = true;
    return Status::Ok;
  }
  m->values = values;
  if (shift != 0.0) {
    for (int slot : m->diagonal_slots) {
      if (slot < 0) throw std::invalid_argument("IndefiniteFactorization: a shift needs every diagonal entry in the pattern");
      m->values[static_cast<size_t>(slot)] += shift;
    }
  }
  std::lock_guard<std::mutex> guard(mumps_lock());
  DMUMPS_STRUC_C& mumps = m->mumps;
  mumps.n = m->n;
  mumps.nnz = static_cast<int64_t>(m->rows.size());
  mumps.irn = m->rows.data();
  mumps.jcn = m->columns.data();
  mumps.a = m->values.data();
  if (!m->analysed) {
    m->call(JOB_ANALYSE);
    if (mumps.infog[0] < 0) return Status::Failed;
    m->analysed = true;
    // INFO(8): the estimated size of S, in millions of entries when negative; half as much again for
    // delayed pivots. A workspace that is large enough already is kept.
    const double estimate = mumps.info[7] >= 0 ? mumps.info[7] : -1e6 * mumps.info[7];
    if (estimate * sizeof(double) > GLIBC_LARGEST_RECYCLED_BLOCK && m->workspace.size() < estimate)
      m->use_workspace(static_cast<size_t>(1.5 * estimate) + 1);
  }
  // Delayed pivots can outgrow the workspace estimated at analysis: grow it and factorize again.
  for (int attempt = 0;; ++attempt) {
    m->call(JOB_FACTORIZE);
    const int info = mumps.infog[0];
    const bool workspace = info == WORKSPACE_TOO_SMALL || info == INTEGER_WORKSPACE_TOO_SMALL || info == MEMORY_TOO_SMALL;
    if (workspace && attempt < 4) {
      mumps.icntl[13] = 2 * std::max(mumps.icntl[13], 20);  // ICNTL(14): percentage added to the estimate
      if (info == WORKSPACE_TOO_SMALL && !m->workspace.empty()) m->use_workspace(2 * m->workspace.size());
      continue;
    }
    if (info == NUMERICALLY_SINGULAR) return Status::Singular;
    if (info < 0) return Status::Failed;
    break;
  }
  m_negative = mumps.infog[11];  // INFOG(12): negative pivots, the inertia for a symmetric matrix
  m->factorized = true;
  return Status::Ok;
}

Eigen::VectorXd IndefiniteFactorization::solve(const Eigen::VectorXd& rhs) const { return solve_columns(rhs).col(0); }

Eigen::MatrixXd IndefiniteFactorization::solve_columns(const Eigen::MatrixXd& rhs) const {
  if (!m->factorized) throw std::logic_error("IndefiniteFactorization::solve without a successful factorization");
  if (rhs.rows() != m->n) throw std::invalid_argument("IndefiniteFactorization::solve: size mismatch");
  Eigen::MatrixXd solution = rhs;
  if (m->n == 0 || rhs.cols() == 0) return solution;
  std::lock_guard<std::mutex> guard(mumps_lock());
  DMUMPS_STRUC_C& mumps = m->mumps;
  mumps.rhs = solution.data();
  mumps.nrhs = static_cast<int>(rhs.cols());
  mumps.lrhs = m->n;
  m->call(JOB_SOLVE);
  mumps.rhs = nullptr;
  if (mumps.infog[0] < 0)
    throw std::runtime_error("IndefiniteFactorization::solve: MUMPS error " + std::to_string(mumps.infog[0]));
  return solution;
}

}  // namespace balloon
