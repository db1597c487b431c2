#include "material/pressure_fall_band.hpp"

#include <cmath>
#include <functional>

#include "material/homogeneous_tests.hpp"

namespace balloon {

namespace {

/// Grid of the first search: stretches 1.0005 * GRID_RATIO^k, fine enough that no maximum and minimum
/// fall between two neighbouring points for any law this code knows.
constexpr double GRID_START = 1.0005;
constexpr double GRID_RATIO = 1.005;
constexpr double PLACEMENT_TOLERANCE = 1e-9;

/// The sphere's pressure per (rest thickness / rest radius), in MPa; not a number once the law's
/// exponential stiffening overflows.
double unit_sphere_pressure(const Material& material, double stretch) {
  return sphere_pressure(material, 1.0, 1.0, stretch);
}

/// The stretch in [lo, hi] where `sign * pressure` is largest, by golden-section search (the
/// bracket holds one extremum).
double place_extremum(const std::function<double(double)>& pressure, double lo, double hi, double sign) {
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi;
  double c = b - golden * (b - a), d = a + golden * (b - a);
  double fc = sign * pressure(c), fd = sign * pressure(d);
  while (b - a > PLACEMENT_TOLERANCE) {
    if (fc > fd) {
      b = d, d = c, fd = fc;
      c = b - golden * (b - a), fc = sign * pressure(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + golden * (b - a), fd = sign * pressure(d);
    }
  }
  return 0.5 * (a + b);
}

}  // namespace

bool PressureFallBand::contains(double stretch) const {
  return stretch > from_stretch && (!to_stretch || stretch < *to_stretch);
}

std::optional<PressureFallBand> pressure_fall_band(const Material& material) {
  const auto pressure = [&material](double stretch) { return unit_sphere_pressure(material, stretch); };
  std::optional<PressureFallBand> band;
  double before = GRID_START, here = GRID_START * GRID_RATIO;
  double p_before = pressure(before), p_here = pressure(here);
  for (double next = here * GRID_RATIO; next <= PRESSURE_FALL_SEARCH_STRETCH; next *= GRID_RATIO) {
    const double p_next = pressure(next);
    if (!std::isfinite(p_next)) break;
    if (!band && p_here >= p_before && p_next < p_here) {
      band = PressureFallBand{place_extremum(pressure, before, next, 1.0), std::nullopt};
    } else if (band && p_here <= p_before && p_next > p_here) {
      band->to_stretch = place_extremum(pressure, before, next, -1.0);
      return band;
    }
    before = here, here = next, p_before = p_here, p_here = p_next;
  }
  return band;
}

}  // namespace balloon
