#include "calibration/axisymmetric_bulge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>

namespace balloon {
namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double PI = std::numbers::pi;
/// Start of the integration off the pole, in units of a: the pole is a singular point of the equations
/// (terms in 1/R), the series start below is exact to O(R^2) there.
constexpr double POLE_OFFSET = 1e-4;
/// Rim condition |l2(a) - 1| below which a pressure is accepted.
constexpr double RIM_TOLERANCE = 1e-10;
constexpr int MAX_SHOTS = 80;

/// W = Psi(I1, I2) of the incompressible membrane as a function of the two in-plane stretches, with the
/// derivatives the equations need (w_i = dW/dl_i, w_ij = d2W/dl_i dl_j).
struct StretchDerivatives {
  double w1 = 0, w2 = 0, w11 = 0, w12 = 0;
};

StretchDerivatives stretch_derivatives(const Material& material, double l1, double l2) {
  const double l1s = l1 * l1, l2s = l2 * l2, l3s = 1.0 / (l1s * l2s);
  const double I1 = l1s + l2s + l3s, I2 = 1.0 / l1s + 1.0 / l2s + l1s * l2s;
  const InvariantDerivatives d = strain_energy(material, I1, I2);
  // dI/dl_i and d2I/dl_i dl_j from I1 = l1^2 + l2^2 + l1^-2 l2^-2, I2 = l1^-2 + l2^-2 + l1^2 l2^2.
  const double a1 = 2 * l1 - 2 * l3s / l1, a2 = 2 * l2 - 2 * l3s / l2;
  const double b1 = -2 / (l1s * l1) + 2 * l1 * l2s, b2 = -2 / (l2s * l2) + 2 * l2 * l1s;
  const double a11 = 2 + 6 * l3s / l1s, a12 = 4 * l3s / (l1 * l2);
  const double b11 = 6 / (l1s * l1s) + 2 * l2s, b12 = 4 * l1 * l2;
  StretchDerivatives s;
  s.w1 = d.d1 * a1 + d.d2 * b1;
  s.w2 = d.d1 * a2 + d.d2 * b2;
  s.w11 = d.d11 * a1 * a1 + 2 * d.d12 * a1 * b1 + d.d22 * b1 * b1 + d.d1 * a11 + d.d2 * b11;
  s.w12 = d.d11 * a1 * a2 + d.d12 * (a1 * b2 + a2 * b1) + d.d22 * b1 * b2 + d.d1 * a12 + d.d2 * b12;
  return s;
}

/// State along the meridian (lengths in units of a): l1, l2, phi, depth below the pole, A / (pi a^2) / 2
/// accumulated as integral R l1 l2 dR, and V / a^3.
using State = std::array<double, 6>;

/// One shot from the pole at pole stretch l0 and dimensionless pressure P = p a / H (MPa).
struct Shot {
  bool ok = false;
  double rim = 0.0;     ///< l2(a) - 1: > 0 too little pressure, < 0 too much
  double height = 0.0;  ///< apex height / a
  double area = 0.0;    ///< A / A0
  double volume = 0.0;  ///< V / a^3
};

class Shooter {
 public:
  Shooter(const Material& material, int steps) : m_material(material) {
    // Graded nodes R = R0 + (1 - R0) s^2: short steps near the pole, where the equations are stiff
    // (l1 - l2 relaxes like R^-2), long ones towards the rim where the solution is smooth.
    steps = std::max(steps, 8);
    m_nodes.resize(static_cast<size_t>(steps) + 1);
    for (int k = 0; k <= steps; ++k) {
      const double s = static_cast<double>(k) / steps;
      m_nodes[static_cast<size_t>(k)] = POLE_OFFSET + (1.0 - POLE_OFFSET) * s * s;
    }
  }

  Shot shoot(double l0, double P) const {
    Shot shot;
    const StretchDerivatives s0 = stretch_derivatives(m_material, l0, l0);
    if (!(s0.w1 > 0)) return shot;
    const double R0 = m_nodes.front();
    // Pole series: equibiaxial stretch, meridian curvature p / (2 T) with T = H W_1 / l0 (Laplace).
    const double phi0 = P * l0 * l0 * R0 / (2 * s0.w1);
    State y{l0, l0, phi0, 0.0, 0.5 * R0 * R0 * l0 * l0, 0.0};
    for (size_t k = 0; k + 1 < m_nodes.size(); ++k) {
      const double R = m_nodes[k], h = m_nodes[k + 1] - R;
      State k1, k2, k3, k4, t;
      if (!rhs(R, y, P, k1)) return shot;
      for (int j = 0; j < 6; ++j) t[j] = y[j] + 0.5 * h * k1[j];
      if (!rhs(R + 0.5 * h, t, P, k2)) return shot;
      for (int j = 0; j < 6; ++j) t[j] = y[j] + 0.5 * h * k2[j];
      if (!rhs(R + 0.5 * h, t, P, k3)) return shot;
      for (int j = 0; j < 6; ++j) t[j] = y[j] + h * k3[j];
      if (!rhs(R + h, t, P, k4)) return shot;
      for (int j = 0; j < 6; ++j) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    }
    if (!std::isfinite(y[0] + y[1] + y[2] + y[3] + y[4] + y[5])) return shot;
    shot.ok = true;
    shot.rim = y[1] - 1.0;
    shot.height = y[3];
    shot.area = 2.0 * y[4];
    shot.volume = y[5];
    return shot;
  }

 private:
  /// Right-hand side of the membrane equations (see the header); false when the state left the physical
  /// range (a stretch <= 0, or a material that gives no tension), which counts as too much pressure.
  bool rhs(double R, const State& y, double P, State& d) const {
    const double l1 = y[0], l2 = y[1], phi = y[2];
    if (!(l1 > 0.05 && l2 > 0.05 && l1 < 1e3 && l2 < 1e3)) return false;
    const StretchDerivatives s = stretch_derivatives(m_material, l1, l2);
    if (!(s.w1 > 0 && s.w11 > 0)) return false;
    const double c = std::cos(phi), sn = std::sin(phi);
    const double dl2 = (l1 * c - l2) / R;
    d[0] = (s.w2 * c - s.w1 - R * s.w12 * dl2) / (R * s.w11);
    d[1] = dl2;
    d[2] = (l1 * l2 * P - s.w2 * sn / R) / s.w1;
    d[3] = l1 * sn;
    d[4] = R * l1 * l2;
    const double r = R * l2;
    d[5] = PI * r * r * l1 * sn;
    return true;
  }

  Material m_material;
  std::vector<double> m_nodes;
};

/// A solved state in dimensionless form (pressure P = p a / H in MPa, lengths in a).
struct Point {
  double t = 0;  ///< sqrt(l0 - 1), the curve parameter
  double pressure = 0, height = 0, area_ratio = 1, volume = 0;
};

/// The pressure that closes the rim for pole stretch l0, starting from `guess` (> 0): bracket, then
/// Illinois regula falsi (superlinear, never leaves the bracket). NaN when no pressure does.
double rim_pressure(const Shooter& shooter, double l0, double guess, Shot& shot) {
  auto F = [&](double P, Shot& out) {
    out = shooter.shoot(l0, P);
    return out.ok ? out.rim : -1.0;  // a failed shot has curled the meridian: too much pressure
  };
  int shots = 0;
  // At P = 0 the disc stays flat with l2(a) = l0 > 1: F(0) > 0 is known without a shot.
  double lo = 0.0, f_lo = l0 - 1.0, hi = guess, f_hi;
  Shot at_hi;
  f_hi = F(hi, at_hi);
  ++shots;
  if (f_hi > 0) {
    // Too little pressure: move up in small then growing steps, keeping the last positive point.
    double step = 0.02 * guess;
    while (f_hi > 0) {
      lo = hi;
      f_lo = f_hi;
      hi = lo + step;
      step *= 3;
      f_hi = F(hi, at_hi);
      if (++shots > MAX_SHOTS / 2 || hi > 1e12) return NaN;
    }
  } else {
    // Too much: come down towards the guess side, keeping the last negative point.
    double candidate = 0.98 * guess;
    Shot at_candidate;
    double f_candidate = F(candidate, at_candidate);
    ++shots;
    while (f_candidate < 0) {
      hi = candidate;
      f_hi = f_candidate;
      candidate *= 0.7;
      f_candidate = F(candidate, at_candidate);
      if (++shots > MAX_SHOTS / 2 || candidate < 1e-300) return NaN;
    }
    lo = candidate;
    f_lo = f_candidate;
    if (std::abs(f_lo) <= RIM_TOLERANCE && at_candidate.ok) {
      shot = at_candidate;
      return lo;
    }
  }
  int side = 0;  // Illinois: halve the stale end's value when the same end moves twice
  while (shots < MAX_SHOTS) {
    const double P = (f_lo * hi - f_hi * lo) / (f_lo - f_hi);
    Shot at;
    const double f = F(P, at);
    ++shots;
    if (at.ok && std::abs(f) <= RIM_TOLERANCE) {
      shot = at;
      return P;
    }
    if (f > 0) {
      lo = P;
      f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = P;
      f_hi = f;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
    if (hi - lo <= 1e-14 * hi) break;
  }
  return NaN;
}

/// Dimensionless material: the leading modulus (and C2 with it for Mooney-Rivlin) divided out, so the
/// response of `material` is scale * the response of the shape.
double split_scale(const Material& material, Material& shape) {
  shape = material;
  const double scale = material.params[0];
  shape.params[0] = 1.0;
  if (material.model == MaterialModel::MooneyRivlin) shape.params[1] = material.params[1] / scale;
  return scale;
}

/// Traces the dimensionless curve of `shape` until both extents are reached (area ratio, height / a).
struct DimensionlessCurve {
  bool converged = false;
  std::string message;
  std::vector<Point> points;
};

DimensionlessCurve trace(const Material& shape, double max_area_ratio, double max_height,
                         const AxisymmetricBulgeOptions& options) {
  DimensionlessCurve curve;
  curve.points.push_back(Point{});
  const Shooter shooter(shape, options.steps);
  const double dt = options.pole_stretch_step > 0 ? options.pole_stretch_step : 0.08;
  // Small strain: a clamped membrane's pressure grows like the cube of its height, and the pole strain
  // like its square, so P ~ c t^3 in t = sqrt(l0 - 1); c ~ 20 W_1'(1) starts the first bracket.
  const StretchDerivatives s1 = stretch_derivatives(shape, 1.0 + 1e-3, 1.0 + 1e-3);
  const double stiffness = std::max(s1.w1 / 1e-3, 1e-12);
  double t = 0.0;
  int past_extent = 0;
  for (int k = 1; k < options.max_points; ++k) {
    t += k == 1 ? 0.5 * dt : dt;
    const double l0 = 1.0 + t * t;
    if (l0 > options.max_pole_stretch) {
      curve.message = "pole stretch limit " + std::to_string(options.max_pole_stretch) + " reached";
      return curve;
    }
    // Predict the pressure by extrapolating the last points (quadratic in t), else the small-strain law.
    double guess = 2.0 * stiffness * t * t * t;
    const size_t n = curve.points.size();
    if (n >= 3) {
      const Point &a = curve.points[n - 3], &b = curve.points[n - 2], &c = curve.points[n - 1];
      const double la = ((t - b.t) * (t - c.t)) / ((a.t - b.t) * (a.t - c.t));
      const double lb = ((t - a.t) * (t - c.t)) / ((b.t - a.t) * (b.t - c.t));
      const double lc = ((t - a.t) * (t - b.t)) / ((c.t - a.t) * (c.t - b.t));
      const double predicted = la * a.pressure + lb * b.pressure + lc * c.pressure;
      if (predicted > 0) guess = predicted;
    } else if (n == 2) {
      guess = curve.points[1].pressure * std::pow(t / curve.points[1].t, 3);
    }
    Shot shot;
    const double P = rim_pressure(shooter, l0, guess, shot);
    if (!std::isfinite(P)) {
      curve.message = "no pressure closes the rim at pole stretch " + std::to_string(l0);
      return curve;
    }
    curve.points.push_back(Point{t, P, shot.height, shot.area, shot.volume});
    // Two points past the extent, so the last interval used has centred slopes on both sides.
    if (shot.area >= max_area_ratio && shot.height >= max_height && ++past_extent > 2) {
      curve.converged = true;
      curve.message = "converged";
      return curve;
    }
  }
  curve.message = "point limit " + std::to_string(options.max_points) + " reached";
  return curve;
}

/// Curve quantities divided by their small-strain power of t = sqrt(l0 - 1) (P ~ t^3, A / A0 - 1 ~ t^2,
/// h ~ t): smooth with finite limits at the flat disc, so cubic interpolation in t stays accurate down to
/// the first point instead of fighting the cusp of p(rho) at rho = 1.
double scaled_pressure(const Point& p) { return p.pressure / (p.t * p.t * p.t); }
double scaled_area(const Point& p) { return (p.area_ratio - 1.0) / (p.t * p.t); }
double scaled_height(const Point& p) { return p.height / p.t; }

/// The scaled quantities are smooth functions of the strain l0 - 1 = t^2, so even in t: near the flat disc
/// they follow a + b t^2 through the first two points.
double even_coefficient(const std::vector<Point>& points, double (*value)(const Point&)) {
  return (value(points[2]) - value(points[1])) / (points[2].t * points[2].t - points[1].t * points[1].t);
}

/// Cubic Hermite interpolation of v(t) over the points after the flat disc (index >= 1), slopes by finite
/// differences on the non-uniform neighbours (exact for quadratics), from the even fit at the first point,
/// one-sided at the last (the curve runs two points past what it is asked for).
double slope(const std::vector<Point>& points, size_t k, double (*value)(const Point&)) {
  const size_t n = points.size();
  if (n < 3) return 0.0;
  if (k <= 1) return 2.0 * even_coefficient(points, value) * points[1].t;
  if (k == n - 1) return (value(points[k]) - value(points[k - 1])) / (points[k].t - points[k - 1].t);
  const double h0 = points[k].t - points[k - 1].t, h1 = points[k + 1].t - points[k].t;
  const double d0 = (value(points[k]) - value(points[k - 1])) / h0, d1 = (value(points[k + 1]) - value(points[k])) / h1;
  return (h1 * d0 + h0 * d1) / (h0 + h1);
}

/// v(t) in the step [t_k, t_k+1] (k >= 1); below the first point (k = 0) the even fit a + b t^2.
double hermite(const std::vector<Point>& points, size_t k, double t, double (*value)(const Point&)) {
  if (k == 0) {
    if (points.size() < 3) return value(points[1]);
    return value(points[1]) + even_coefficient(points, value) * (t * t - points[1].t * points[1].t);
  }
  const double h = points[k + 1].t - points[k].t, u = (t - points[k].t) / h;
  const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u), h01 = u * u * (3 - 2 * u),
               h11 = u * u * (u - 1);
  return h00 * value(points[k]) + h10 * h * slope(points, k, value) + h01 * value(points[k + 1]) +
         h11 * h * slope(points, k + 1, value);
}

/// A curve coordinate: its raw value at a point, its scaled form and the power of t between them.
struct Coordinate {
  double (*raw)(const Point&);
  double (*scaled)(const Point&);
  int power;
};
double area_excess(const Point& p) { return p.area_ratio - 1.0; }
double height_of(const Point& p) { return p.height; }
constexpr Coordinate AREA{area_excess, scaled_area, 2};
constexpr Coordinate HEIGHT{height_of, scaled_height, 1};

/// Dimensionless pressure where the coordinate reaches `target` (first crossing), NaN beyond the curve.
double pressure_where(const std::vector<Point>& points, double target, const Coordinate& coordinate) {
  for (size_t k = 0; k + 1 < points.size(); ++k) {
    const double c0 = coordinate.raw(points[k]), c1 = coordinate.raw(points[k + 1]);
    if (!(target >= c0 && target <= c1)) continue;
    // Bisection on the interpolated coordinate: monotone within a step in practice, and cheap.
    auto at = [&](double t) { return std::pow(t, coordinate.power) * hermite(points, k, t, coordinate.scaled); };
    double lo = points[k].t, hi = points[k + 1].t;
    for (int i = 0; i < 60 && hi - lo > 1e-15 * hi; ++i) {
      const double mid = 0.5 * (lo + hi);
      (at(mid) < target ? lo : hi) = mid;
    }
    const double t = 0.5 * (lo + hi);
    return t * t * t * hermite(points, k, t, scaled_pressure);
  }
  return NaN;
}

AxisymmetricBulgeState dimensional(const Point& point, double scale, double radius_mm, double thickness_mm) {
  AxisymmetricBulgeState state;
  state.converged = true;
  state.pole_stretch = 1.0 + point.t * point.t;
  state.pressure_kpa = 1e3 * scale * point.pressure * thickness_mm / radius_mm;
  state.apex_height_mm = point.height * radius_mm;
  state.extension_ratio = std::sqrt(point.area_ratio);
  state.volume_mm3 = point.volume * radius_mm * radius_mm * radius_mm;
  return state;
}

/// Pressures (kPa) of `set` from a dimensionless curve of its shape.
std::vector<double> pressures_from(const DimensionlessCurve& curve, double scale, const MeasurementSet& set) {
  const bool heights = set.apex_height_mm.size() == set.x.size() && !set.x.empty();
  std::vector<double> p(set.x.size(), NaN);
  const double to_kpa = 1e3 * scale * set.thickness_mm / set.disc_radius_mm;
  for (size_t i = 0; i < set.x.size(); ++i) {
    const double value = heights ? set.apex_height_mm[i] / set.disc_radius_mm : set.x[i] * set.x[i] - 1.0;
    if (value <= 0.0) {
      p[i] = 0.0;
      continue;
    }
    p[i] = to_kpa * pressure_where(curve.points, value, heights ? HEIGHT : AREA);
  }
  return p;
}

/// The extents (area ratio, height / a) a set needs.
std::pair<double, double> extents(const MeasurementSet& set) {
  const bool heights = set.apex_height_mm.size() == set.x.size() && !set.x.empty();
  double area = 1.0, height = 0.0;
  for (size_t i = 0; i < set.x.size(); ++i) {
    if (heights)
      height = std::max(height, set.apex_height_mm[i] / set.disc_radius_mm);
    else
      area = std::max(area, set.x[i] * set.x[i]);
  }
  return {area, height};
}

bool usable_geometry(const MeasurementSet& set) {
  return std::isfinite(set.disc_radius_mm) && set.disc_radius_mm > 0 && std::isfinite(set.thickness_mm) &&
         set.thickness_mm > 0;
}

}  // namespace

AxisymmetricBulgeState axisymmetric_bulge_at_pole_stretch(const Material& material, double radius_mm,
                                                          double thickness_mm, double pole_stretch,
                                                          const AxisymmetricBulgeOptions& options) {
  AxisymmetricBulgeState state;
  if (!(pole_stretch > 1.0) || !(radius_mm > 0) || !(thickness_mm > 0) || !material_problem(material).empty())
    return state;
  Material shape;
  const double scale = split_scale(material, shape);
  // Follow the curve up to the requested stretch so the pressure bracket starts from a good guess.
  AxisymmetricBulgeOptions traced = options;
  traced.max_pole_stretch = pole_stretch;
  const DimensionlessCurve curve = trace(shape, std::numeric_limits<double>::infinity(), 0.0, traced);
  const Shooter shooter(shape, options.steps);
  const Point& last = curve.points.back();
  const double t = std::sqrt(pole_stretch - 1.0);
  const double guess = last.t > 0 ? last.pressure * std::pow(t / last.t, 3) : 1.0;
  Shot shot;
  const double P = rim_pressure(shooter, pole_stretch, std::max(guess, 1e-12), shot);
  if (!std::isfinite(P)) return state;
  return dimensional(Point{t, P, shot.height, shot.area, shot.volume}, scale, radius_mm, thickness_mm);
}

double AxisymmetricBulgeCurve::pressure_at_extension_ratio(double extension_ratio) const {
  if (extension_ratio <= 1.0) return 0.0;
  std::vector<Point> dimensionless;
  for (const AxisymmetricBulgeState& s : points)
    dimensionless.push_back(Point{std::sqrt(s.pole_stretch - 1.0), s.pressure_kpa, 0.0,
                                  s.extension_ratio * s.extension_ratio, 0.0});
  return pressure_where(dimensionless, extension_ratio * extension_ratio - 1.0, AREA);
}

double AxisymmetricBulgeCurve::pressure_at_apex_height(double apex_height_mm) const {
  if (apex_height_mm <= 0.0) return 0.0;
  std::vector<Point> dimensionless;
  for (const AxisymmetricBulgeState& s : points)
    dimensionless.push_back(Point{std::sqrt(s.pole_stretch - 1.0), s.pressure_kpa, s.apex_height_mm, 1.0, 0.0});
  return pressure_where(dimensionless, apex_height_mm, HEIGHT);
}

AxisymmetricBulgeCurve axisymmetric_bulge_curve(const Material& material, double radius_mm, double thickness_mm,
                                                double max_extension_ratio, double max_apex_height_mm,
                                                const AxisymmetricBulgeOptions& options) {
  AxisymmetricBulgeCurve curve;
  if (!(radius_mm > 0) || !(thickness_mm > 0) || !std::isfinite(radius_mm) || !std::isfinite(thickness_mm)) {
    curve.message = "the disc needs a positive radius and thickness (mm)";
    return curve;
  }
  if (const std::string problem = material_problem(material); !problem.empty()) {
    curve.message = problem;
    return curve;
  }
  Material shape;
  const double scale = split_scale(material, shape);
  const DimensionlessCurve traced =
      trace(shape, max_extension_ratio * max_extension_ratio, max_apex_height_mm / radius_mm, options);
  curve.converged = traced.converged;
  curve.message = traced.message;
  for (const Point& point : traced.points) curve.points.push_back(dimensional(point, scale, radius_mm, thickness_mm));
  curve.points.front().pole_stretch = 1.0;
  return curve;
}

std::vector<double> axisymmetric_bulge_pressures(const Material& material, const MeasurementSet& set,
                                                 const AxisymmetricBulgeOptions& options) {
  if (!usable_geometry(set) || !material_problem(material).empty() || set.x.empty())
    return std::vector<double>(set.x.size(), NaN);
  Material shape;
  const double scale = split_scale(material, shape);
  const auto [area, height] = extents(set);
  return pressures_from(trace(shape, area, height, options), scale, set);
}

BulgeModel axisymmetric_bulge_model(const AxisymmetricBulgeOptions& options) {
  // The last few dimensionless curves, by shape: Levenberg-Marquardt's steps and Jacobian columns along
  // the leading modulus change only the scale.
  struct Cached {
    Material shape;
    double area = 1.0, height = 0.0;
    DimensionlessCurve curve;
  };
  struct Cache {
    std::mutex mutex;
    std::vector<Cached> entries;  // most recent last
  };
  auto cache = std::make_shared<Cache>();
  return [cache, options](const Material& material, const MeasurementSet& set) {
    if (!usable_geometry(set) || !material_problem(material).empty() || set.x.empty())
      return std::vector<double>(set.x.size(), NaN);
    Material shape;
    const double scale = split_scale(material, shape);
    const auto [area, height] = extents(set);
    std::lock_guard<std::mutex> lock(cache->mutex);
    for (const Cached& entry : cache->entries)
      if (entry.shape.model == shape.model && entry.shape.params == shape.params && entry.area >= area &&
          entry.height >= height)
        return pressures_from(entry.curve, scale, set);
    Cached entry{shape, area, height, trace(shape, area, height, options)};
    std::vector<double> p = pressures_from(entry.curve, scale, set);
    constexpr size_t CAPACITY = 8;
    if (cache->entries.size() >= CAPACITY) cache->entries.erase(cache->entries.begin());
    cache->entries.push_back(std::move(entry));
    return p;
  };
}

}  // namespace balloon
