#pragma once
/// Where a rubber's balloon loses pressure as it grows. A thin sphere's inflation pressure
/// (homogeneous_tests.hpp, sphere_pressure) rises to a maximum, and for most rubbers falls past it
/// until the rubber's stiffening makes it rise again at a minimum. Between the two, a part of a
/// balloon that stretches further needs less pressure, not more: a long or thin part inflated there
/// can stop growing evenly, one region bulging while the rest stays small, as a long party balloon does.
/// The band depends on the law alone: the sphere's radius and wall thickness only scale its pressure.
#include <optional>

#include "material/material.hpp"

namespace balloon {

/// The stretches r / R (dimensionless) between which the sphere law's pressure falls as it stretches.
struct PressureFallBand {
  double from_stretch = 1.0;            ///< the pressure maximum
  std::optional<double> to_stretch;     ///< the minimum past it; none where the pressure keeps falling
  /// True when `stretch` lies between the maximum and the minimum (past the maximum, without one).
  bool contains(double stretch) const;
};

/// The largest stretch searched (a volume ratio of 125,000); extrema beyond it are not reported.
constexpr double PRESSURE_FALL_SEARCH_STRETCH = 50.0;

/// The band of `material`, or none when its sphere pressure rises all the way to
/// PRESSURE_FALL_SEARCH_STRETCH (a rubber that stiffens before it could soften). Both ends are placed
/// to about 1e-7 in stretch (a search by pressure values alone resolves an extremum to the square root
/// of the rounding).
std::optional<PressureFallBand> pressure_fall_band(const Material& material);

}  // namespace balloon
