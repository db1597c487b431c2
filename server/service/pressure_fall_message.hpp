#pragma once
/// balloon.v1.PressureFallBand filled from the core's band (material/pressure_fall_band.hpp): the
/// design and simulate reports carry it with their surface's share, a material with none.
#include <optional>

#include "balloon/v1/balloon.pb.h"
#include "material/pressure_fall_band.hpp"

namespace balloon::service {

/// The band's ends as stretches and as a sphere's volume ratios (stretch^3), and `area_share` when known.
void fill_pressure_fall(const PressureFallBand& band, const std::optional<double>& area_share,
                        balloon::v1::PressureFallBand& out);

}  // namespace balloon::service
