#include "material/pressure_fall_band.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "material/homogeneous_tests.hpp"

namespace balloon {
namespace {

/// The law a SPEC names (material.hpp), e.g. "neo-hookean:mu=0.3".
Material law(const std::string& spec) { return parse_material_spec(spec).value(); }

double slope(const Material& m, double stretch) {
  const double h = 1e-6;
  return (sphere_pressure(m, 1, 1, stretch + h) - sphere_pressure(m, 1, 1, stretch - h)) / (2 * h);
}

/// For Mooney-Rivlin the sphere pressure is (4 C1 H / R)(1/l - 1/l^7)(1 + a l^2), a = C2 / C1, whose
/// extrema are the roots x = l^2 of a x^4 - x^3 + 5 a x + 7 = 0: found here by bisection on its own.
double mooney_rivlin_extremum(double a, double lo, double hi) {
  const auto f = [a](double l) {
    const double x = l * l;
    return a * x * x * x * x - x * x * x + 5 * a * x + 7;
  };
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(PressureFallBand, NeoHookeanFallsForeverPastSeventhRootOfSeven) {
  const auto band = pressure_fall_band(law("neo-hookean:mu=0.3"));
  ASSERT_TRUE(band);
  EXPECT_NEAR(band->from_stretch, std::pow(7.0, 1.0 / 6.0), 1e-7);
  EXPECT_FALSE(band->to_stretch);
  EXPECT_FALSE(band->contains(1.38));
  EXPECT_TRUE(band->contains(1.39));
  EXPECT_TRUE(band->contains(40.0));
}

TEST(PressureFallBand, MooneyRivlinEndsWhereItsClosedFormHasItsExtrema) {
  const double a = 0.1;  // C2 / C1
  const auto band = pressure_fall_band(law("mooney-rivlin:C1=0.2,C2=0.02"));
  ASSERT_TRUE(band);
  ASSERT_TRUE(band->to_stretch);
  // f(l) changes sign between 1.3 and 1.6 (the maximum) and between 1.6 and 4 (the minimum).
  EXPECT_NEAR(band->from_stretch, mooney_rivlin_extremum(a, 1.3, 1.6), 1e-7);
  EXPECT_NEAR(*band->to_stretch, mooney_rivlin_extremum(a, 1.6, 4.0), 1e-7);
  // A larger C2 / C1 (about 0.21 and above) keeps the pressure rising: no band.
  EXPECT_FALSE(pressure_fall_band(law("mooney-rivlin:C1=0.2,C2=0.06")));
}

TEST(PressureFallBand, PresetsFallBetweenTheirMaximumAndMinimum) {
  // Reference values from a 0.001-step scan of the closed form, independent of the search here.
  struct Case {
    const char* preset;
    double from, to;
  } cases[] = {{"latex", 1.365, 3.966}, {"silicone", 1.406, 1.620}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.preset);
    const Material m = preset_material(c.preset).value();
    const auto band = pressure_fall_band(m);
    ASSERT_TRUE(band);
    ASSERT_TRUE(band->to_stretch);
    EXPECT_NEAR(band->from_stretch, c.from, 2e-3);
    EXPECT_NEAR(*band->to_stretch, c.to, 2e-3);
    // Both ends are extrema: the slope vanishes there on the scale of the pressure per unit stretch.
    const double scale = sphere_pressure(m, 1, 1, band->from_stretch);
    EXPECT_NEAR(slope(m, band->from_stretch) / scale, 0.0, 1e-5);
    EXPECT_NEAR(slope(m, *band->to_stretch) / scale, 0.0, 1e-5);
    const double middle = 0.5 * (band->from_stretch + *band->to_stretch);
    EXPECT_LT(slope(m, middle), 0.0);
    EXPECT_TRUE(band->contains(middle));
    EXPECT_FALSE(band->contains(*band->to_stretch + 0.01));
  }
}

TEST(PressureFallBand, AStrongStiffeningWithoutAMaximumHasNoBand) {
  // k1 = 1 stiffens before the neo-Hookean part can peak: the pressure rises until the law overflows.
  EXPECT_FALSE(pressure_fall_band(law("hart-smith:G=0.15,k1=1,k2=0.8")));
}

}  // namespace
}  // namespace balloon
