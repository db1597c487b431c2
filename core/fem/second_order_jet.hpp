#pragma once
/// A scalar with its gradient and Hessian with respect to N variables, and the chain rule for the few
/// operations the membrane energy needs. Internal to core/fem: the element derivatives are written as
/// compositions of small closed-form steps instead of one long expression.
/// With WithHessian false the jet carries the gradient only, computed by the very same expressions: the
/// residuals and line searches need no Hessian (the knot with Mooney-Rivlin x8: 18.7 -> 16.2 s, same steps).
#include <Eigen/Core>
#include <cmath>
#include <type_traits>

namespace balloon::fem {

namespace jet_detail {
struct NoHessian {};

template <int N, bool WithHessian>
auto zero_hessian() {
  if constexpr (WithHessian) return Eigen::Matrix<double, N, N>::Zero().eval();
  else return NoHessian{};
}
}  // namespace jet_detail

template <int N, bool WithHessian = true>
struct Jet {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  double v = 0.0;
  Vec g = Vec::Zero();
  std::conditional_t<WithHessian, Mat, jet_detail::NoHessian> h = jet_detail::zero_hessian<N, WithHessian>();

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

template <int N, bool H>
Jet<N, H> operator+(const Jet<N, H>& a, const Jet<N, H>& b) {
  Jet<N, H> r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  if constexpr (H) r.h = a.h + b.h;
  return r;
}

template <int N, bool H>
Jet<N, H> operator-(const Jet<N, H>& a, const Jet<N, H>& b) {
  Jet<N, H> r;
  r.v = a.v - b.v;
  r.g = a.g - b.g;
  if constexpr (H) r.h = a.h - b.h;
  return r;
}

template <int N, bool H>
Jet<N, H> operator*(double s, const Jet<N, H>& a) {
  Jet<N, H> r;
  r.v = s * a.v;
  r.g = s * a.g;
  if constexpr (H) r.h = s * a.h;
  return r;
}

template <int N, bool H>
Jet<N, H> operator*(const Jet<N, H>& a, const Jet<N, H>& b) {
  Jet<N, H> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  if constexpr (H) r.h = a.v * b.h + b.v * a.h + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}

/// f(a) given f, f', f'' at a.v.
template <int N, bool H>
Jet<N, H> apply(const Jet<N, H>& a, double f, double df, double ddf) {
  Jet<N, H> r;
  r.v = f;
  r.g = df * a.g;
  if constexpr (H) r.h = df * a.h + ddf * a.g * a.g.transpose();
  return r;
}

template <int N, bool H>
Jet<N, H> inverse(const Jet<N, H>& a) {
  const double inv = 1.0 / a.v;
  return apply(a, inv, -inv * inv, 2.0 * inv * inv * inv);
}

template <int N, bool H>
Jet<N, H> operator/(const Jet<N, H>& a, const Jet<N, H>& b) {
  return a * inverse(b);
}

template <int N, bool H>
Jet<N, H> sqrt(const Jet<N, H>& a) {
  const double s = std::sqrt(a.v);
  return apply(a, s, 0.5 / s, -0.25 / (s * a.v));
}

/// f(a, b) given the value, gradient (fa, fb) and Hessian (faa, fab, fbb) of f at (a.v, b.v).
template <int N, bool H>
Jet<N, H> apply2(const Jet<N, H>& a, const Jet<N, H>& b, double f, double fa, double fb, double faa, double fab,
                 double fbb) {
  Jet<N, H> r;
  r.v = f;
  r.g = fa * a.g + fb * b.g;
  if constexpr (H)
    r.h = fa * a.h + fb * b.h + faa * a.g * a.g.transpose() + fbb * b.g * b.g.transpose() +
          fab * (a.g * b.g.transpose() + b.g * a.g.transpose());
  return r;
}

}  // namespace balloon::fem
