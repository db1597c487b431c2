#include "design/lbfgs.hpp"

#include <Eigen/CholmodSupport>
#include <vector>

namespace balloon {

struct Lbfgs::Preconditioner {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> factorization;
};

Lbfgs::Lbfgs(int memory) : m_memory(memory) {}
Lbfgs::~Lbfgs() = default;

void Lbfgs::set_preconditioner(Eigen::SparseMatrix<double> hessian) {
  const double shift = 1e-3 * hessian.diagonal().mean();
  for (int c = 0; c < hessian.rows(); ++c) hessian.coeffRef(c, c) += shift;
  m_preconditioner = std::make_unique<Preconditioner>();
  m_preconditioner->factorization.compute(hessian);
  if (m_preconditioner->factorization.info() != Eigen::Success) m_preconditioner.reset();
}

Eigen::VectorXd Lbfgs::precondition(const Eigen::VectorXd& q) const {
  if (!m_preconditioner) return q;
  Eigen::VectorXd r = m_preconditioner->factorization.solve(q);
  return r.allFinite() ? r : q;
}

Eigen::VectorXd Lbfgs::apply(const Eigen::VectorXd& gradient) const {
  Eigen::VectorXd q = gradient;
  std::vector<double> alpha(m_pairs.size());
  for (int i = static_cast<int>(m_pairs.size()) - 1; i >= 0; --i) {
    const auto& [s, y] = m_pairs[static_cast<size_t>(i)];
    alpha[static_cast<size_t>(i)] = s.dot(q) / y.dot(s);
    q -= alpha[static_cast<size_t>(i)] * y;
  }
  q = precondition(q);
  if (!m_pairs.empty()) {
    const auto& [s, y] = m_pairs.back();
    q *= s.dot(y) / y.dot(precondition(y));
  }
  for (size_t i = 0; i < m_pairs.size(); ++i) {
    const auto& [s, y] = m_pairs[i];
    const double beta = y.dot(q) / y.dot(s);
    q += (alpha[i] - beta) * s;
  }
  return q;
}

void Lbfgs::update(const Eigen::VectorXd& step, const Eigen::VectorXd& change) {
  if (!(step.dot(change) > 1e-12 * step.norm() * change.norm())) return;
  m_pairs.emplace_back(step, change);
  if (static_cast<int>(m_pairs.size()) > m_memory) m_pairs.pop_front();
}

}  // namespace balloon
