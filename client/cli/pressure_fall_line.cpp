#include "pressure_fall_line.hpp"

#include "cli_output.hpp"

namespace balloon::cli {

std::string pressure_fall_range(const v1::PressureFallBand& band) {
  if (band.has_to_stretch())
    return "between stretch " + format("%.4g", band.from_stretch()) + " and " + format("%.4g", band.to_stretch()) +
           " (volume ratio " + format("%.3g", band.from_volume_ratio()) + " to " +
           format("%.3g", band.to_volume_ratio()) + ")";
  return "past stretch " + format("%.4g", band.from_stretch()) + " (volume ratio " +
         format("%.3g", band.from_volume_ratio()) + ")";
}

std::string pressure_fall_line(const v1::PressureFallBand& band) {
  std::string line = "  rubber         its pressure falls as it stretches " + pressure_fall_range(band);
  if (!band.has_area_share()) return line + "\n";
  line += format("; %.0f%% of the inflated surface is stretched there", 100.0 * band.area_share());
  if (band.area_share() > PRESSURE_FALL_ADVICE_SHARE) {
    line += ": long or thin parts of a balloon there can bulge one at a time instead of inflating evenly (as a "
            "long party balloon does); a volume ratio below " +
            format("%.3g", band.from_volume_ratio());
    if (band.has_to_volume_ratio()) line += " or above " + format("%.3g", band.to_volume_ratio());
    line += " keeps the sheet out of it";
  }
  return line + "\n";
}

}  // namespace balloon::cli
