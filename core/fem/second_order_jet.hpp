#pragma once
/// A scalar with its gradient and Hessian with respect to N variables, and the chain rule for the few
/// operations the membrane energy needs. Internal to core/fem: the element derivatives are written as
/// compositions of small closed-form steps instead of one long expression.
#include <Eigen/Core>
#include <cmath>

namespace balloon::fem {

template <int N>
struct Jet {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  double v = 0.0;
  Vec g = Vec::Zero();
  Mat h = Mat::Zero();

  static Jet constant(double value) {
    Jet j;
    j.v = value;
    return j;
  }
  static Jet variable(double value, int index) {
    Jet j = constant(value);
    j.g[index] = 1.0;
    return j;
  }
};

template <int N>
Jet<N> operator+(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  r.h = a.h + b.h;
  return r;
}

template <int N>
Jet<N> operator-(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  r.v = a.v - b.v;
  r.g = a.g - b.g;
  r.h = a.h - b.h;
  return r;
}

template <int N>
Jet<N> operator*(double s, const Jet<N>& a) {
  Jet<N> r;
  r.v = s * a.v;
  r.g = s * a.g;
  r.h = s * a.h;
  return r;
}

template <int N>
Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  r.h = a.v * b.h + b.v * a.h + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}

/// f(a) given f, f', f'' at a.v.
template <int N>
Jet<N> apply(const Jet<N>& a, double f, double df, double ddf) {
  Jet<N> r;
  r.v = f;
  r.g = df * a.g;
  r.h = df * a.h + ddf * a.g * a.g.transpose();
  return r;
}

template <int N>
Jet<N> inverse(const Jet<N>& a) {
  const double inv = 1.0 / a.v;
  return apply(a, inv, -inv * inv, 2.0 * inv * inv * inv);
}

template <int N>
Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  return a * inverse(b);
}

template <int N>
Jet<N> sqrt(const Jet<N>& a) {
  const double s = std::sqrt(a.v);
  return apply(a, s, 0.5 / s, -0.25 / (s * a.v));
}

/// f(a, b) given the value, gradient (fa, fb) and Hessian (faa, fab, fbb) of f at (a.v, b.v).
template <int N>
Jet<N> apply2(const Jet<N>& a, const Jet<N>& b, double f, double fa, double fb, double faa, double fab,
              double fbb) {
  Jet<N> r;
  r.v = f;
  r.g = fa * a.g + fb * b.g;
  r.h = fa * a.h + fb * b.h + faa * a.g * a.g.transpose() + fbb * b.g * b.g.transpose() +
        fab * (a.g * b.g.transpose() + b.g * a.g.transpose());
  return r;
}

}  // namespace balloon::fem
