#pragma once
/// The design a maker gets is never worse, inflated from rest, than one the run already checked that way.
#include "design/balloon_design.hpp"
#include "design/surface_distance.hpp"
#include "solve/inflation.hpp"

namespace balloon {

/// Where the final design, inflated from rest as a maker inflates it, ends clearly farther (more than 1%)
/// from the target than another rest shape checked from rest during the run (the start, or an earlier
/// design), or finds no
/// equilibrium there, that rest shape is checked again the same way and, where it still does better, is
/// handed back with the shape it reaches: what the maker gets is never worse than a design the run
/// already knew. (Latex bunny, x27, 20 s: the last design took another shape from rest at
/// 8.6 mm, three times the downscaled target's 2.8 mm, and was handed back.) The log keeps every iterate.
/// `result.from_rest` holds the final design's check, made with `inflation` (material, thickness, time
/// limit, cancel token); nothing changes without it or without result.closest_from_rest.
void hand_back_closest_from_rest(const TriMesh& target, const SurfaceDistance& target_surface,
                                 InflationOptions inflation, DesignResult& result);

}  // namespace balloon
