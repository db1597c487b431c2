#include "design/balloon_design.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "design/augmented_lagrangian_design.hpp"
#include "design/closest_from_rest.hpp"
#include "design/design_driver.hpp"
#include "design/multiresolution_design.hpp"
#include "design/reduced_space_design.hpp"
#include "design/rest_inflation_check.hpp"
#include "material/pressure_fall_share.hpp"
#include "material/thin_sheet.hpp"
#include "mesh/centred_frame.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {

std::string design_method_name(DesignMethod method) {
  return method == DesignMethod::Adjoint ? "adjoint" : "alm";
}

std::string design_stop_name(DesignStop stop) {
  switch (stop) {
    case DesignStop::Matched: return "matched";
    case DesignStop::Optimal: return "optimal";
    case DesignStop::Stalled: return "stalled";
    case DesignStop::TimeLimit: return "time_limit";
    case DesignStop::IterationLimit: return "iteration_limit";
    case DesignStop::StartFailed: return "start_failed";
    case DesignStop::Cancelled: return "cancelled";
  }
  return "stalled";
}

Result<DesignMethod> parse_design_method(const std::string& name) {
  if (name == "adjoint") return DesignMethod::Adjoint;
  if (name == "alm") return DesignMethod::AugmentedLagrangian;
  return fail("unknown design method '" + name + "' (known: adjoint, alm)");
}

namespace {

/// Why the options or the target cannot be designed for, or "" when they can.
std::string options_problem(const TriMesh& target, const DesignOptions& options) {
  if (target.vertex_count() < 4 || target.face_count() < 4) return "the target mesh is empty";
  if (auto problem = material_problem(options.material); !problem.empty()) return problem;
  if (auto problem = thickness_problem(options.thickness_mm); !problem.empty()) return problem;
  if (options.scale > 0) {
    if (!(options.scale < 1.0)) return "scale must be below 1: the balloon starts smaller than the target";
  } else if (!(options.volume_ratio > 1.0) || !std::isfinite(options.volume_ratio)) {
    return "volume ratio must be a number above 1";
  }
  if (!(enclosed_volume(target.vertices, target.faces) > 0.0)) return "the target encloses no positive volume";
  // The start is the target scaled down (by S, or to 1/R of its volume): that is the sheet's balloon.
  if (auto problem =
          thin_sheet_problem(options.thickness_mm, design_start_scale(options) * bounding_box_diagonal(target.vertices));
      !problem.empty())
    return problem;
  if (!(options.k_length >= 0.0 && options.k_bending >= 0.0 && options.k_surface >= 0.0) ||
      !std::isfinite(options.k_length + options.k_bending + options.k_surface))
    return "the objective's weights must be finite and not negative";
  if (!(options.surface_growth >= 1.0 && options.max_surface_growth >= 1.0) ||
      !std::isfinite(options.surface_growth * options.max_surface_growth) || options.surface_growth_iterations < 1)
    return "the surface term's growth must be a finite factor of at least 1, after at least 1 iteration";
  if (options.initial_rest.rows() != 0) {
    if (options.initial_rest.rows() != target.vertex_count() || !options.initial_rest.allFinite())
      return "the initial rest shape must have one finite position per target vertex";
    if (!(enclosed_volume(options.initial_rest, target.faces) > 0.0))
      return "the initial rest shape encloses no positive volume";
  }
  for (int v : options.nozzle_vertices)
    if (v < 0 || v >= target.vertex_count()) return "nozzle vertex " + std::to_string(v) + " does not exist";
  return "";
}

DesignResult run_optimizer(const TriMesh& target, const DesignOptions& options) {
  if (runs_coarse_to_fine(target, options)) return design_coarse_to_fine(target, options);
  DesignDriver driver(target, options);
  if (options.method == DesignMethod::AugmentedLagrangian) return run_augmented_lagrangian_design(driver);
  return run_reduced_space_design(driver);
}

/// Inflates the design's rest shape from rest as `balloon simulate` would (rest_inflation_check.hpp);
/// nothing when there is no design or the run was cancelled.
void add_rest_inflation_check(const TriMesh& target, const DesignOptions& options, DesignResult& result) {
  const bool have_design = result.avg_error_mm && result.volume_ratio && result.rest.vertex_count() > 0 &&
                           result.inflated.rows() == result.rest.vertex_count();
  if (!have_design || result.stop == DesignStop::Cancelled) return;
  if (options.progress) {
    ProgressEvent event;
    event.phase = "check";
    event.elapsed_s = result.time_s;
    options.progress(event);
  }
  // The forward solver's own path settings, as balloon simulate uses them, on a free balloon as the
  // design's (a nozzle holds rest vertices in the design, not the inflated sheet).
  InflationOptions inflation;
  inflation.material = options.material;
  inflation.thickness_mm = options.thickness_mm;
  inflation.control = InflationControl::VolumeRatio;
  inflation.volume_ratio = *result.volume_ratio;
  inflation.max_time_s = REST_INFLATION_CHECK_TIME_LIMIT_S;
  inflation.cancel = options.cancel;
  const SurfaceDistance target_surface(target);
  result.from_rest = check_inflation_from_rest(result.rest, inflation, result.inflated, *result.avg_error_mm,
                                               target_surface, target.vertices);
  hand_back_closest_from_rest(target, target_surface, inflation, result);
}

/// The rubber's band of falling pressure, and how much of the handed-back inflated shape lies in it.
void add_pressure_fall(const DesignOptions& options, DesignResult& result) {
  result.pressure_fall = pressure_fall_band(options.material);
  const bool have_design = result.avg_error_mm && result.rest.vertex_count() > 0 &&
                           result.inflated.rows() == result.rest.vertex_count();
  if (result.pressure_fall && have_design)
    result.pressure_fall_area_share = area_share_in_pressure_fall(result.rest, result.inflated, *result.pressure_fall);
}

/// The design in the target's centred frame (mesh/centred_frame.hpp): refuse what cannot be designed,
/// then set up the run and hand it to the chosen optimizer.
DesignResult design_centred(const TriMesh& target, const DesignOptions& options) {
  if (auto problem = options_problem(target, options); !problem.empty()) {
    DesignResult result;
    result.method = options.method;
    result.stop = DesignStop::StartFailed;
    result.message = problem;
    result.rest = target;
    result.inflated = target.vertices;
    return result;
  }
  DesignResult result = run_optimizer(target, options);
  if (options.check_from_rest) add_rest_inflation_check(target, options, result);
  add_pressure_fall(options, result);
  return result;
}

/// Progress whose shapes reach the caller in its own frame.
ProgressCallback in_caller_frame(const CentredFrame& frame, ProgressCallback progress) {
  if (!progress) return progress;
  return [frame, progress = std::move(progress)](const ProgressEvent& event) {
    ProgressEvent moved = event;
    Positions shape, rest_shape;
    if (event.shape) moved.shape = &(shape = frame.caller(*event.shape));
    if (event.rest_shape) moved.rest_shape = &(rest_shape = frame.caller(*event.rest_shape));
    progress(moved);
  };
}

}  // namespace

double design_start_scale(const DesignOptions& options) {
  return options.scale > 0 ? options.scale : std::cbrt(1.0 / options.volume_ratio);
}

/// The entry point (reduced_space_design.hpp, augmented_lagrangian_design.hpp): designed about the
/// target's bounding-box centre, every position handed back where the caller's target stands.
DesignResult design_balloon(const TriMesh& caller_target, const DesignOptions& caller_options) {
  const CentredFrame frame(caller_target.vertices);
  const TriMesh target{frame.centred(caller_target.vertices), caller_target.faces};
  DesignOptions options = caller_options;
  options.initial_rest = frame.centred(caller_options.initial_rest);
  if (options.resume) options.resume->rest = frame.centred(options.resume->rest);
  options.progress = in_caller_frame(frame, caller_options.progress);

  DesignResult result = design_centred(target, options);
  result.rest.vertices = frame.caller(result.rest.vertices);
  result.inflated = frame.caller(result.inflated);
  if (result.from_rest) result.from_rest->shape = frame.caller(result.from_rest->shape);
  if (result.closest_from_rest) result.closest_from_rest->rest = frame.caller(result.closest_from_rest->rest);
  return result;
}

}  // namespace balloon
