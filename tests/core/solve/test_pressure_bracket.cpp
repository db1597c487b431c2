// PressureBracket: the volumes at which pressure control looks for its target between two path points.
// Near the rest the pressure is a power of the added volume (exponent 1 curved, 3 flat); the bracket must
// find such a target in a step or two from the stress-free rest, and any continuous p(V) in the end.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "solve/pressure_bracket.hpp"

namespace balloon {
namespace {

constexpr double REST_VOLUME = 1000.0;  // mm^3

/// Narrows a bracket on p(V) until the pressure is within `relative` of the target; returns the
/// volume solves that took (or -1 after 60) and checks that each next volume lies inside the bracket.
int solves_to_reach(const std::function<double(double)>& pressure_at, double target, double high_volume,
                    double relative = 1e-9) {
  PressureBracket bracket(REST_VOLUME, target, {REST_VOLUME, 0.0}, {high_volume, pressure_at(high_volume)});
  for (int solve = 1; solve <= 60; ++solve) {
    const double volume = bracket.next_volume();
    EXPECT_GT(volume, bracket.low().volume);
    EXPECT_LT(volume, bracket.high().volume);
    const double pressure = pressure_at(volume);
    if (std::abs(pressure / target - 1.0) <= relative) return solve;
    bracket.narrow({volume, pressure});
  }
  return -1;
}

TEST(PressureBracket, AFlatFacesCubicLawIsReachedInOneSolveFromRest) {
  // The path's first point at 1.5 V_rest has 270 times the target pressure (a rounded box's first step).
  const auto cubic = [](double v) { return 2e-3 * std::pow((v - REST_VOLUME) / 500.0, 3); };
  EXPECT_EQ(solves_to_reach(cubic, 2e-3 / 270.0, 1.5 * REST_VOLUME), 1);
}

TEST(PressureBracket, ACurvedSheetsLinearLawIsReachedInTwoSolvesFromRest) {
  // The flat face's exponent overshoots once; the two high ends then measure the exponent exactly.
  const auto linear = [](double v) { return 2e-3 * (v - REST_VOLUME) / 500.0; };
  EXPECT_EQ(solves_to_reach(linear, 2e-3 / 270.0, 1.5 * REST_VOLUME), 2);
}

TEST(PressureBracket, AnyPowerLawIsReachedInAFewSolves) {
  for (const double exponent : {0.7, 1.5, 2.0, 2.5, 3.5}) {
    const auto power = [exponent](double v) { return std::pow((v - REST_VOLUME) / 100.0, exponent); };
    const int solves = solves_to_reach(power, 1e-3, 2.0 * REST_VOLUME);
    EXPECT_GE(solves, 1) << "exponent " << exponent;
    EXPECT_LE(solves, 4) << "exponent " << exponent;
  }
}

TEST(PressureBracket, ACurveWithAnOffsetAndAMaximumBeyondTheBracketStillCloses) {
  // Not a power law of the added volume: a rubber's curve rising to a maximum past the bracket, from a
  // path point above the rest (the bracket's low end has pressure). Illinois closes it all the same.
  const auto rising = [](double v) {
    const double ratio = v / REST_VOLUME;
    return 0.05 + std::pow(ratio, -1.0 / 3.0) - std::pow(ratio, -7.0 / 3.0) - 0.2 * (ratio - 1.0) * (ratio - 1.0);
  };
  const double low = 1.2 * REST_VOLUME, high = 1.6 * REST_VOLUME;
  const double target = 0.5 * (rising(low) + rising(high));
  PressureBracket bracket(REST_VOLUME, target, {low, rising(low)}, {high, rising(high)});
  int solves = 0;
  for (; solves < 60; ++solves) {
    const double volume = bracket.next_volume();
    if (std::abs(rising(volume) / target - 1.0) <= 1e-9) break;
    bracket.narrow({volume, rising(volume)});
  }
  EXPECT_LE(solves, 8);
}

TEST(PressureBracket, EndsBelowTheRestVolumeFallBackToLinearInterpolation) {
  // No logarithm of a negative added volume: regula falsi on the pressures, inside the bracket.
  PressureBracket bracket(REST_VOLUME, 1.0, {0.5 * REST_VOLUME, 0.0}, {1.5 * REST_VOLUME, 4.0});
  EXPECT_NEAR(bracket.next_volume(), 0.75 * REST_VOLUME, 1e-9);
}

}  // namespace
}  // namespace balloon
