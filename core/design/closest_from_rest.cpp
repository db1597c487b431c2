#include "design/closest_from_rest.hpp"

#include <string>
#include <utility>

#include "design/rest_inflation_check.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

/// How much farther from the target, inflated from rest, the final design must end than the closest
/// candidate for that candidate to be handed back: a percent, well above the checks' own noise.
constexpr double CLEARLY_FARTHER = 1.01;

}  // namespace

void hand_back_closest_from_rest(const TriMesh& target, const SurfaceDistance& target_surface,
                                 InflationOptions inflation, DesignResult& result) {
  if (!result.from_rest || !result.closest_from_rest) return;
  const RestInflationCheck& final_check = *result.from_rest;
  const CheckedFromRest& closest = *result.closest_from_rest;
  const bool final_has_no_equilibrium = !final_check.converged && (final_check.stop == InflationStop::NoEquilibrium ||
                                                                   final_check.stop == InflationStop::PassesThroughItself);
  // The final design may be that candidate itself (a design matched at its start), whose two checks differ
  // by rounding only: a 642-vertex sphere matched after 0 iterations was reported stalled, its start
  // "handed back" for 0.0035149514115865375 mm against 0.0035149514115865063 mm.
  if (closest.rest == result.rest.vertices) return;
  const bool final_is_farther =
      final_check.converged && *final_check.avg_error_mm > CLEARLY_FARTHER * closest.avg_error_mm;
  if (!final_has_no_equilibrium && !final_is_farther) return;
  const TriMesh closest_rest{closest.rest, target.faces};
  inflation.volume_ratio = enclosed_volume(target.vertices, target.faces) / enclosed_volume(closest.rest, target.faces);
  // Compared with the target itself: its deviation from "the design's shape" is set below, as it is
  // the shape handed back.
  RestInflationCheck again = check_inflation_from_rest(closest_rest, inflation, target.vertices, 0.0,
                                                       target_surface, target.vertices);
  if (!again.converged || (final_is_farther && !(*again.avg_error_mm < *final_check.avg_error_mm))) return;

  const std::string which = closest.iteration == 0 ? std::string("the start (the downscaled target)")
                                                   : "the design of iteration " + std::to_string(closest.iteration);
  const std::string final_verdict = final_is_farther ? "reaches " + millimetres(*final_check.avg_error_mm) + " from the target"
                                                     : "finds no equilibrium (" + final_check.inflation_message + ")";
  const std::string handed_back = "inflated from rest, the last design " + final_verdict + ", so " + which +
                                  " is handed back (" + millimetres(*again.avg_error_mm) + " from the target from rest)";
  if (result.converged) {
    // The criterion held for the last design on its own branch, not for the one handed back.
    result.message = "stalled: the last design was " + design_stop_name(result.stop) +
                     " on the branch the design followed (" + result.message + "), but " + handed_back;
    result.converged = false;
    result.stop = DesignStop::Stalled;
  } else {
    result.message += "; " + handed_back;
  }
  result.rest.vertices = closest.rest;
  result.inflated = again.shape;
  result.pressure_kpa = again.pressure_kpa;
  result.volume_ratio = inflation.volume_ratio;
  result.avg_error_mm = again.avg_error_mm;
  result.max_error_mm = again.max_error_mm;
  result.avg_error_rel = again.avg_error_rel;
  result.max_error_rel = again.max_error_mm ? std::optional<double>(*again.max_error_mm / result.bbox_diag_mm)
                                            : std::nullopt;
  result.residual_norm = again.residual_norm;
  result.distance_energy.reset();  // not evaluated for this shape
  again.deviation_mm = 0.0;  // the shape handed back is the one reached from rest
  again.another_shape = false;
  again.message = "inflated from rest, as balloon simulate does, " + which + " takes the shape handed back: avg error " +
                  millimetres(*again.avg_error_mm);
  result.from_rest = std::move(again);
}

}  // namespace balloon
