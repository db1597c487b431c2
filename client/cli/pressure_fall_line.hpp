#pragma once
/// The `rubber` line of the design and simulate summaries: where the rubber's pressure falls as it
/// stretches (balloon.v1.PressureFallBand) and how much of the inflated surface is stretched there.
#include <string>

#include "balloon/v1/balloon.pb.h"

namespace balloon::cli {

/// Above this share of the inflated surface in the band, the line says what that can do to a balloon
/// and which volume ratios avoid it.
constexpr double PRESSURE_FALL_ADVICE_SHARE = 0.5;

/// Where the band lies: "between stretch 1.365 and 3.966 (volume ratio 2.55 to 62.4)", or "past stretch
/// ..." for a band without a minimum.
std::string pressure_fall_range(const v1::PressureFallBand& band);

/// The line, indented and ended like the other summary lines.
std::string pressure_fall_line(const v1::PressureFallBand& band);

}  // namespace balloon::cli
