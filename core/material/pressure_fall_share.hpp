#pragma once
/// How much of an inflated balloon is stretched where its rubber loses pressure as it grows
/// (pressure_fall_band.hpp). In that band a balloon's long or thin parts can bulge one at a
/// time instead of inflating evenly, and a design may then not reach its target; a volume ratio
/// outside the band keeps the sheet out of it.
#include "material/pressure_fall_band.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// The share (0..1) of `inflated`'s surface area whose triangles are stretched into `band`, each by
/// sqrt(inflated area / rest area), the stretch of a sphere inflated to that area. `inflated` holds
/// one position per vertex of `rest`.
double area_share_in_pressure_fall(const TriMesh& rest, const Positions& inflated, const PressureFallBand& band);

}  // namespace balloon
