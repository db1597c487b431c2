#pragma once
/// curve.csv and curve.svg of a pressure-volume curve (balloon.v1.CurveReport), written by these two
/// functions for every path (balloon simulate --volume-ratio-range, balloon jobs result, the HTTP files route).
#include <string>

#include "balloon/v1/balloon.pb.h"

namespace balloon::contract {

/// The curve as CSV: header `volume_ratio,pressure_kpa,mean_stretch,max_stretch,unstable_modes,converged`,
/// one row per point in path order. A value never computed is an empty cell (never 0); converged is
/// `true` or `false`; numbers as in report.json (shortest text that reads back to the same double).
std::string curve_csv(const balloon::v1::CurveReport& report);

/// The curve as an SVG plot: pressure (kPa, linear) against volume ratio (log scale), one marker per
/// converged point (hollow where unstable_modes > 0), the pressure maxima and minima marked and labelled.
std::string curve_svg(const balloon::v1::CurveReport& report);

}  // namespace balloon::contract
