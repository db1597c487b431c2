#pragma once
/// How much of an inflated balloon is stretched where its rubber loses pressure as it grows
/// (material/pressure_fall_band.hpp). A balloon mostly inside that band inflates evenly only where
/// it is one round chamber: its long or thin parts bulge one at a time instead, so a design there may
/// not reach its target whatever its rest shape, and a volume ratio outside the band can.
#include "material/pressure_fall_band.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// The share (0..1) of `inflated`'s surface area whose triangles are stretched into `band`, each by
/// sqrt(inflated area / rest area), the stretch of a sphere inflated to that area. `inflated` holds
/// one position per vertex of `rest`.
double area_share_in_pressure_fall(const TriMesh& rest, const Positions& inflated, const PressureFallBand& band);

}  // namespace balloon
