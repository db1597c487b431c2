#include "design/rest_inflation_check.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace balloon {

std::string millimetres(double value_mm) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g mm", value_mm);
  return text;
}

double deviation_from_design_mm(const Positions& shape, const Positions& design_inflated, const Faces& faces) {
  return SurfaceDistance(TriMesh{design_inflated, faces}).aligned_stats(shape, design_inflated).avg_mm;
}

bool is_another_shape(double deviation_mm, double design_avg_error_mm, double bbox_diag_mm) {
  return deviation_mm > std::max(design_avg_error_mm, ANOTHER_SHAPE_MIN_REL * bbox_diag_mm);
}

RestInflationCheck check_inflation_from_rest(const TriMesh& rest, const InflationOptions& options,
                                             const Positions& design_inflated, double design_avg_error_mm,
                                             const SurfaceDistance& target, const Positions& target_vertices) {
  const auto started = std::chrono::steady_clock::now();
  RestInflationCheck check;
  const InflationResult inflated = inflate(rest, options);
  check.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  check.converged = inflated.converged;
  check.stop = inflated.stop;
  check.inflation_message = inflated.message;
  if (!inflated.converged) {
    check.message = "inflated from rest, as balloon simulate does, it did not reach the design's volume: " +
                    inflated.message;
    return check;
  }
  const SurfaceDistanceStats error = target.aligned_stats(inflated.deformed, target_vertices);
  check.avg_error_mm = error.avg_mm;
  check.max_error_mm = error.max_mm;
  check.avg_error_rel = error.avg_rel;
  check.pressure_kpa = inflated.pressure_kpa;
  check.shape = rigid_align_to(inflated.deformed, target_vertices);
  check.residual_norm = inflated.residual_norm;
  check.unstable_modes = inflated.unstable_modes;
  check.deviation_mm = deviation_from_design_mm(inflated.deformed, design_inflated, rest.faces);
  check.another_shape = is_another_shape(*check.deviation_mm, design_avg_error_mm, error.bbox_diag_mm);
  const std::string reached = "avg error " + millimetres(error.avg_mm) + " (" +
                              millimetres(*check.deviation_mm) + " from the design's shape on average)";
  check.message = check.another_shape
                      ? "inflated from rest, as balloon simulate does, it takes another shape: " + reached +
                            "; the design's error holds only on the branch the design followed"
                      : "inflated from rest, as balloon simulate does, it takes the design's shape: " + reached;
  return check;
}

}  // namespace balloon
