#include "jobs/design_job.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "design/mold.hpp"
#include "material/thin_sheet.hpp"
#include "jobs/json_writer.hpp"
#include "jobs/mesh_size.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon::jobs {
namespace {

/// The largest inflation a design accepts (V / V0); latex, the stretchiest rubber, reaches about 125.
constexpr double MAX_VOLUME_RATIO = 1000.0;

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

/// The start's size against the target's (design_start_scale), absent values at DesignOptions' defaults.
double start_scale(const DesignParameters& parameters) {
  DesignOptions options;
  if (parameters.scale) options.scale = *parameters.scale;
  if (parameters.volume_ratio) options.volume_ratio = *parameters.volume_ratio;
  return design_start_scale(options);
}

/// The mold tube for `rest`: at the nozzle the design held (scaled to the rest shape), or at the lowest
/// point when none was asked. A radius too wide for the surface around the nozzle is halved (3 tries).
DesignOutcome& find_mold(const DesignInput& input, DesignOutcome& outcome) {
  const TriMesh& rest = outcome.result.rest;
  MoldParameters mold;
  if (input.nozzle) {
    mold.nozzle_vertex = input.nozzle->center_vertex;
    mold.tube_radius_mm = input.nozzle->radius_mm * input.start_scale;
  } else {
    NozzleSpec automatic;
    automatic.automatic = true;
    Result<NozzleSelection> selection = select_nozzle(rest, automatic);
    if (!selection) {
      outcome.mold_problem = "no nozzle for the mold: " + selection.error();
      return outcome;
    }
    mold.nozzle_vertex = selection->center_vertex;
    mold.tube_radius_mm = selection->radius_mm;
  }
  mold.tube_length_mm = MOLD_TUBE_LENGTH_FRACTION * bounding_box_diagonal(rest.vertices);
  std::string problem;
  for (int attempt = 0; attempt < 4; ++attempt, mold.tube_radius_mm *= 0.5) {
    Result<TriMesh> built = design_mold(rest, mold);
    if (built) {
      outcome.mold = mold;
      outcome.mold_mesh = std::move(*built);
      outcome.mold_problem.clear();
      return outcome;
    }
    if (problem.empty()) problem = built.error();
  }
  outcome.mold_problem = problem;
  return outcome;
}

}  // namespace

std::vector<FieldProblem> design_parameter_problems(const DesignParameters& parameters) {
  std::vector<FieldProblem> problems;
  const auto problem = [&](const char* field, std::string message) { problems.push_back({field, std::move(message)}); };
  if (std::string thickness = thickness_problem(parameters.thickness_mm); !thickness.empty())
    problem("thickness_mm", std::move(thickness));
  if (std::string size = size_mm_problem(parameters.size_mm); !size.empty()) problem("size_mm", std::move(size));
  if (parameters.resolution < 0)
    problem("resolution", "resolution must be >= 0 vertices (0 never remeshes)");
  else if (parameters.resolution > 0 && parameters.resolution < 50)
    problem("resolution", "resolution must be at least 50 vertices (or 0 to keep the target's), got " +
                              std::to_string(parameters.resolution));
  // A balloon inflated more than MAX_VOLUME_RATIO-fold (scale below its cube root) is no rubber's: refused
  // here rather than failing deep in the solver (a start shrunk to nothing has zero-length edges).
  if (parameters.scale && parameters.volume_ratio)
    problem("scale", "give either a scale or a volume ratio, not both");
  // The start is the target shrunk (scale below 1, volume ratio above 1): the balloon inflates into it.
  else if (parameters.scale &&
           (!std::isfinite(*parameters.scale) || *parameters.scale < std::cbrt(1.0 / MAX_VOLUME_RATIO) || *parameters.scale >= 1.0))
    problem("scale", "scale must be a number of at least " + format_number(std::cbrt(1.0 / MAX_VOLUME_RATIO)) +
                         " and below 1, got " + format_number(*parameters.scale));
  else if (parameters.volume_ratio &&
           (!std::isfinite(*parameters.volume_ratio) || *parameters.volume_ratio <= 1.0 ||
            *parameters.volume_ratio > MAX_VOLUME_RATIO))
    problem("volume_ratio", "volume ratio must be a positive number above 1 and up to " + format_number(MAX_VOLUME_RATIO) +
                                ", got " + format_number(*parameters.volume_ratio));
  if (!parameters.method.empty()) {
    Result<DesignMethod> method = parse_design_method(parameters.method);
    if (!method) problem("method", "method: " + method.error());
  }
  if (!parameters.nozzle.empty()) {
    Result<NozzleSpec> nozzle = parse_nozzle(parameters.nozzle);
    if (!nozzle) problem("nozzle", "nozzle: " + nozzle.error());
  }
  if (!std::isfinite(parameters.max_time_s) || parameters.max_time_s < 0.0)
    problem("max_time_s", "max time must be a number of s >= 0 (0 means none), got " + format_number(parameters.max_time_s));
  if (parameters.tolerance_samples < 0 || parameters.tolerance_samples > MAX_TOLERANCE_SAMPLES)
    problem("tolerance_samples", "tolerance samples must be within 0.." + std::to_string(MAX_TOLERANCE_SAMPLES));
  return problems;
}

std::string design_size_problem(const DesignParameters& parameters, double target_diagonal_mm) {
  const double diagonal_mm = parameters.size_mm > 0.0 ? parameters.size_mm : target_diagonal_mm;
  if (std::string problem = mesh_size_problem(diagonal_mm); !problem.empty()) return problem;
  return thin_sheet_problem(parameters.thickness_mm, start_scale(parameters) * diagonal_mm);
}

Result<DesignInput> prepare_design(TriMesh target, const Material& material, const DesignParameters& parameters) {
  if (const std::vector<FieldProblem> problems = design_parameter_problems(parameters); !problems.empty())
    return fail(problems.front().message);
  if (const std::string problem = material_problem(material); !problem.empty()) return fail("material: " + problem);

  TargetPreparationOptions preparation;
  preparation.size_mm = parameters.size_mm;
  preparation.resolution = parameters.resolution;
  Result<PreparedTarget> prepared = prepare_target(std::move(target), preparation);
  if (!prepared) return fail("mesh: " + prepared.error());

  DesignInput input;
  input.target = std::move(*prepared);
  input.material = material;
  input.parameters = parameters;
  input.method = parameters.method.empty() ? DesignOptions{}.method : *parse_design_method(parameters.method);
  input.start_scale = start_scale(parameters);
  if (const std::string problem = design_size_problem(parameters, bounding_box_diagonal(input.target.mesh.vertices));
      !problem.empty())
    return fail("mesh: " + problem);
  if (!parameters.nozzle.empty()) {
    Result<NozzleSelection> selection = select_nozzle(input.target.mesh, *parse_nozzle(parameters.nozzle));
    if (!selection) return fail("nozzle: " + selection.error());
    input.nozzle = std::move(*selection);
  }
  return input;
}

Result<TriMesh> design_mold(const TriMesh& rest, const MoldParameters& mold) {
  if (mold.nozzle_vertex < 0 || mold.nozzle_vertex >= rest.vertex_count())
    return fail("mold nozzle vertex " + std::to_string(mold.nozzle_vertex) + " is not a vertex of the rest mesh");
  const Eigen::Vector3d center = rest.vertices.row(mold.nozzle_vertex).transpose();
  return build_mold(rest, center, mold.tube_radius_mm, mold.tube_length_mm);
}

DesignOutcome run_design(const DesignInput& input, const RunControls& controls,
                         const std::optional<DesignCheckpoint>& resume) {
  DesignOptions options;
  options.material = input.material;
  options.thickness_mm = input.parameters.thickness_mm;
  if (input.parameters.scale) options.scale = *input.parameters.scale;
  if (input.parameters.volume_ratio) options.volume_ratio = *input.parameters.volume_ratio;
  options.method = input.method;
  if (input.nozzle) options.nozzle_vertices = input.nozzle->vertices;
  options.max_time_s = input.parameters.max_time_s;
  if (controls.max_time_s > 0.0)
    options.max_time_s = options.max_time_s > 0.0 ? std::min(options.max_time_s, controls.max_time_s) : controls.max_time_s;
  options.progress = controls.progress;
  options.cancel = controls.cancel;
  options.resume = resume;

  DesignOutcome outcome;
  outcome.result = design_balloon(input.target.mesh, options);
  const auto cancelled = [&] { return controls.cancel != nullptr && controls.cancel->cancelled(); };
  if (cancelled()) {
    outcome.cancelled = true;
    return outcome;
  }
  const bool have_design = outcome.result.rest.vertex_count() > 0 &&
                           outcome.result.inflated.rows() == outcome.result.rest.vertex_count();
  if (have_design && input.parameters.tolerance_samples > 0) {
    if (controls.progress) {
      ProgressEvent event;
      event.phase = "tolerance";
      event.elapsed_s = outcome.result.time_s;
      controls.progress(event);
    }
    InflationOptions nominal;
    nominal.material = input.material;
    nominal.thickness_mm = input.parameters.thickness_mm;
    if (input.nozzle) nominal.fixed_vertices = input.nozzle->vertices;
    nominal.cancel = controls.cancel;
    // The design's inflated shape is aligned to the target, not in the rest frame where the nozzle holds
    // its vertices: re-inflate the nominal design in place so every sample starts from its equilibrium.
    nominal.control = InflationControl::VolumeRatio;
    nominal.volume_ratio = outcome.result.volume_ratio.value_or(DesignOptions{}.volume_ratio);
    const InflationResult reference = inflate(outcome.result.rest, nominal);
    const Positions& nominal_shape = reference.converged ? reference.deformed : outcome.result.inflated;
    outcome.tolerance = thickness_tolerance(outcome.result.rest, nominal, nominal_shape,
                                            input.parameters.tolerance_samples, TOLERANCE_SEED);
    if (cancelled()) {
      outcome.cancelled = true;
      outcome.tolerance.reset();
    }
  }
  if (have_design)
    find_mold(input, outcome);
  else
    outcome.mold_problem = "the design produced no rest shape";
  return outcome;
}

std::string design_error_summary(const DesignResult& result) {
  if (!result.avg_error_mm || !result.avg_error_rel)
    return "no design error (stop reason " + design_stop_name(result.stop) + ")";
  char text[128];
  std::snprintf(text, sizeof(text), "avg error %.3g mm (%.2g%% of %.3g mm)", *result.avg_error_mm,
                100.0 * *result.avg_error_rel, result.bbox_diag_mm);
  return text;
}

std::string convergence_csv(const std::vector<ConvergenceSample>& log) {
  std::string csv = "time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n";
  for (const ConvergenceSample& sample : log) {
    csv += json_number(sample.time_s) + "," + std::to_string(sample.iteration) + "," + json_number(sample.avg_error_mm) +
           "," + json_number(sample.max_error_mm) + "," + json_number(sample.residual_norm) + "\n";
  }
  return csv;
}

}  // namespace balloon::jobs
