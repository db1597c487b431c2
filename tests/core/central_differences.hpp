#pragma once
/// Central differences, the truth every energy's gradient, Hessian and mixed derivative is tested against.
#include <Eigen/Core>

namespace balloon::test {

/// Gradient of a scalar f at x: entry i is (f(x + h e_i) - f(x - h e_i)) / 2h.
template <class Vector, class Function>
Vector central_difference_gradient(const Function& f, const Vector& x, double h) {
  Vector gradient = x;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Vector plus = x, minus = x;
    plus[i] += h;
    minus[i] -= h;
    gradient[i] = (f(plus) - f(minus)) / (2 * h);
  }
  return gradient;
}

/// Jacobian of a vector f at x: column i is (f(x + h e_i) - f(x - h e_i)) / 2h.
template <class Vector, class Function>
Eigen::MatrixXd central_difference_jacobian(const Function& f, const Vector& x, double h) {
  Eigen::MatrixXd jacobian;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Vector plus = x, minus = x;
    plus[i] += h;
    minus[i] -= h;
    const Eigen::VectorXd column = (f(plus) - f(minus)) / (2 * h);
    if (i == 0) jacobian.resize(column.size(), x.size());
    jacobian.col(i) = column;
  }
  return jacobian;
}

}  // namespace balloon::test
