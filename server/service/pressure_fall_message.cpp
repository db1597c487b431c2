#include "service/pressure_fall_message.hpp"

#include <cmath>

namespace balloon::service {

void fill_pressure_fall(const PressureFallBand& band, const std::optional<double>& area_share,
                        balloon::v1::PressureFallBand& out) {
  out.set_from_stretch(band.from_stretch);
  out.set_from_volume_ratio(std::pow(band.from_stretch, 3));
  if (band.to_stretch) {
    out.set_to_stretch(*band.to_stretch);
    out.set_to_volume_ratio(std::pow(*band.to_stretch, 3));
  }
  if (area_share) out.set_area_share(*area_share);
}

}  // namespace balloon::service
