#include "axisymmetric_membrane.hpp"

#include <array>
#include <cmath>
#include <functional>

namespace balloon::testing {
namespace {

/// W(l1, l2) = Psi(I1, I2) of the incompressible membrane and its derivatives in the stretches.
struct StretchDerivatives {
  double w1 = 0, w2 = 0, w11 = 0, w12 = 0;
};

StretchDerivatives stretch_derivatives(const Material& material, double l1, double l2) {
  const double I1 = l1 * l1 + l2 * l2 + 1 / (l1 * l1 * l2 * l2);
  const double I2 = 1 / (l1 * l1) + 1 / (l2 * l2) + l1 * l1 * l2 * l2;
  const InvariantDerivatives d = strain_energy(material, I1, I2);
  // dI/dl and second derivatives (by hand from the definitions above).
  const double a1 = 2 * l1 - 2 / (l1 * l1 * l1 * l2 * l2), a2 = 2 * l2 - 2 / (l2 * l2 * l2 * l1 * l1);
  const double b1 = -2 / (l1 * l1 * l1) + 2 * l1 * l2 * l2, b2 = -2 / (l2 * l2 * l2) + 2 * l2 * l1 * l1;
  const double a11 = 2 + 6 / (std::pow(l1, 4) * l2 * l2), a12 = 4 / (std::pow(l1, 3) * std::pow(l2, 3));
  const double b11 = 6 / std::pow(l1, 4) + 2 * l2 * l2, b12 = 4 * l1 * l2;
  StretchDerivatives s;
  s.w1 = d.d1 * a1 + d.d2 * b1;
  s.w2 = d.d1 * a2 + d.d2 * b2;
  s.w11 = d.d11 * a1 * a1 + 2 * d.d12 * a1 * b1 + d.d22 * b1 * b1 + d.d1 * a11 + d.d2 * b11;
  s.w12 = d.d11 * a1 * a2 + d.d12 * (a1 * b2 + a2 * b1) + d.d22 * b1 * b2 + d.d1 * a12 + d.d2 * b12;
  return s;
}

using State = std::array<double, 6>;  // l1, l2, phi, z, area integral, unused

}  // namespace

AxisymmetricBulge integrate_axisymmetric_bulge(const Material& material, double radius_mm, double thickness_mm,
                                               double pole_stretch, double pressure_kpa, int steps) {
  const double p = pressure_kpa * 1e-3;  // MPa
  const double H = thickness_mm;
  auto rhs = [&](double R, const State& y) {
    const double l1 = y[0], l2 = y[1], phi = y[2];
    const StretchDerivatives s = stretch_derivatives(material, l1, l2);
    const double T1 = H * s.w1 / l2, T2 = H * s.w2 / l1;
    const double r = R * l2;
    const double dl2 = (l1 * std::cos(phi) - l2) / R;
    const double dl1 = (s.w2 * std::cos(phi) - s.w1 - R * s.w12 * dl2) / (R * s.w11);
    const double dphi = l1 * (p - T2 * std::sin(phi) / r) / T1;
    State d{dl1, dl2, dphi, -l1 * std::sin(phi), R * l1 * l2, 0.0};
    return d;
  };
  // Series start off the pole: equibiaxial stretch, curvature p / (2 T) so phi = kappa l R.
  const double R0 = 1e-6 * radius_mm;
  const StretchDerivatives s0 = stretch_derivatives(material, pole_stretch, pole_stretch);
  const double T0 = H * s0.w1 / pole_stretch;
  const double kappa = p / (2 * T0);
  State y{pole_stretch, pole_stretch, kappa * pole_stretch * R0, 0.0, 0.5 * R0 * R0 * pole_stretch * pole_stretch, 0.0};
  const double h = (radius_mm - R0) / steps;
  double R = R0;
  AxisymmetricBulge result;
  for (int i = 0; i < steps; ++i) {
    const State k1 = rhs(R, y);
    State t;
    for (int j = 0; j < 6; ++j) t[j] = y[j] + 0.5 * h * k1[j];
    const State k2 = rhs(R + 0.5 * h, t);
    for (int j = 0; j < 6; ++j) t[j] = y[j] + 0.5 * h * k2[j];
    const State k3 = rhs(R + 0.5 * h, t);
    for (int j = 0; j < 6; ++j) t[j] = y[j] + h * k3[j];
    const State k4 = rhs(R + h, t);
    for (int j = 0; j < 6; ++j) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    R += h;
    if (!std::isfinite(y[0]) || y[0] <= 0 || y[1] <= 0) return result;  // the shot left the physical range
  }
  result.ok = true;
  result.pressure_kpa = pressure_kpa;
  result.pole_stretch = pole_stretch;
  result.apex_height_mm = -y[3];  // z(a) = 0 fixes the pole at -z(a) relative to the start
  result.extension_ratio = std::sqrt(2 * y[4] / (radius_mm * radius_mm));
  result.rim_hoop_stretch = y[1];
  return result;
}

AxisymmetricBulge shoot_axisymmetric_bulge(const Material& material, double radius_mm, double thickness_mm,
                                           double pole_stretch) {
  // At p = 0 the disc stays flat with l1 = l2 = pole stretch > 1 at the rim; more pressure curls the
  // meridian and pulls the rim in. Bracket the pressure where r(a) = a, then bisect.
  auto rim = [&](double p) {
    const AxisymmetricBulge b = integrate_axisymmetric_bulge(material, radius_mm, thickness_mm, pole_stretch, p);
    return b.ok ? b.rim_hoop_stretch - 1.0 : -1.0;
  };
  double lo = 0.0, hi = 1e-3 * material.shear_modulus() * 1e3 * thickness_mm / radius_mm;  // kPa
  while (rim(hi) > 0) {
    lo = hi;
    hi *= 2;
    if (hi > 1e9) return {};
  }
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (rim(mid) > 0 ? lo : hi) = mid;
  }
  return integrate_axisymmetric_bulge(material, radius_mm, thickness_mm, pole_stretch, 0.5 * (lo + hi));
}

namespace {
AxisymmetricBulge bisect_pole_stretch(const Material& material, double radius_mm, double thickness_mm,
                                      const std::function<double(const AxisymmetricBulge&)>& measure, double target) {
  double lo = 1.0 + 1e-9, hi = 1.05;
  while (measure(shoot_axisymmetric_bulge(material, radius_mm, thickness_mm, hi)) < target) {
    lo = hi;
    hi = 1.0 + 2 * (hi - 1.0);
    if (hi > 20) return {};
  }
  for (int i = 0; i < 32; ++i) {
    const double mid = 0.5 * (lo + hi);
    (measure(shoot_axisymmetric_bulge(material, radius_mm, thickness_mm, mid)) < target ? lo : hi) = mid;
  }
  return shoot_axisymmetric_bulge(material, radius_mm, thickness_mm, 0.5 * (lo + hi));
}
}  // namespace

AxisymmetricBulge axisymmetric_bulge_at_apex_height(const Material& material, double radius_mm, double thickness_mm,
                                                    double apex_height_mm) {
  return bisect_pole_stretch(material, radius_mm, thickness_mm, [](const AxisymmetricBulge& b) { return b.apex_height_mm; },
                             apex_height_mm);
}

AxisymmetricBulge axisymmetric_bulge_at_extension_ratio(const Material& material, double radius_mm,
                                                        double thickness_mm, double extension_ratio) {
  return bisect_pole_stretch(material, radius_mm, thickness_mm,
                             [](const AxisymmetricBulge& b) { return b.extension_ratio; }, extension_ratio);
}

}  // namespace balloon::testing
