#include "jobs/design_job.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "design/mold.hpp"
#include "jobs/json_reader.hpp"
#include "jobs/json_writer.hpp"
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

double bbox_diagonal(const Positions& vertices) {
  if (vertices.rows() == 0) return 0.0;
  return (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
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
  mold.tube_length_mm = MOLD_TUBE_LENGTH_FRACTION * bbox_diagonal(rest.vertices);
  std::string problem;
  for (int attempt = 0; attempt < 4; ++attempt, mold.tube_radius_mm *= 0.5) {
    Result<TriMesh> built = design_mold(rest, mold);
    if (built) {
      outcome.mold = mold;
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
  if (!std::isfinite(parameters.thickness_mm) || parameters.thickness_mm <= 0.0)
    problem("thickness_mm", "thickness must be a positive number of mm, got " + format_number(parameters.thickness_mm));
  if (!std::isfinite(parameters.size_mm) || parameters.size_mm < 0.0)
    problem("size_mm", "size must be a positive number of mm (or 0 to keep the target's size), got " +
                           format_number(parameters.size_mm));
  if (parameters.resolution < 0)
    problem("resolution", "resolution must be >= 0 vertices (0 never remeshes)");
  else if (parameters.resolution > 0 && parameters.resolution < 50)
    problem("resolution", "resolution must be at least 50 vertices (or 0 to keep the target's), got " +
                              std::to_string(parameters.resolution));
  // A balloon inflated more than MAX_VOLUME_RATIO-fold (scale below its cube root) is no rubber's: refused
  // here rather than failing deep in the solver (a start shrunk to nothing has zero-length edges).
  if (parameters.scale && parameters.volume_ratio)
    problem("scale", "give either a scale or a volume ratio, not both");
  else if (parameters.scale && (!std::isfinite(*parameters.scale) || *parameters.scale < std::cbrt(1.0 / MAX_VOLUME_RATIO)))
    problem("scale", "scale must be a number of at least " + format_number(std::cbrt(1.0 / MAX_VOLUME_RATIO)) +
                         ", got " + format_number(*parameters.scale));
  else if (parameters.volume_ratio &&
           (!std::isfinite(*parameters.volume_ratio) || *parameters.volume_ratio <= 0.0 ||
            *parameters.volume_ratio > MAX_VOLUME_RATIO))
    problem("volume_ratio", "volume ratio must be a positive number up to " + format_number(MAX_VOLUME_RATIO) +
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
  const double volume_ratio = parameters.volume_ratio ? *parameters.volume_ratio : DesignOptions{}.volume_ratio;
  input.start_scale = parameters.scale ? *parameters.scale : std::cbrt(1.0 / volume_ratio);
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

Result<TriMesh> mold_from_report(const TriMesh& rest, const std::string& report_json) {
  Result<JsonValue> report = parse_json(report_json);
  if (!report) return fail("the design report: " + report.error());
  const JsonValue* mold = report->find("mold");
  if (mold == nullptr || mold->kind != JsonValue::Kind::Object) {
    const JsonValue* problem = report->find("mold_problem");
    if (problem != nullptr && problem->kind == JsonValue::Kind::String && !problem->text.empty())
      return fail("the design has no mold: " + problem->text);
    return fail("the design report has no mold");
  }
  const auto number = [&](const char* key) -> Result<double> {
    const JsonValue* value = mold->find(key);
    if (value == nullptr || value->kind != JsonValue::Kind::Number || !std::isfinite(value->number))
      return fail(std::string("the design report's mold has no number '") + key + "'");
    return value->number;
  };
  Result<double> vertex = number("nozzle_vertex");
  Result<double> radius = number("tube_radius_mm");
  Result<double> length = number("tube_length_mm");
  if (!vertex) return fail(vertex.error());
  if (!radius) return fail(radius.error());
  if (!length) return fail(length.error());
  MoldParameters parameters;
  parameters.nozzle_vertex = static_cast<int>(std::lround(*vertex));
  parameters.tube_radius_mm = *radius;
  parameters.tube_length_mm = *length;
  return design_mold(rest, parameters);
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
    outcome.report_json = design_report_json(input, outcome);
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
    nominal.volume_ratio = outcome.result.volume_ratio;
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
  outcome.report_json = design_report_json(input, outcome);
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

std::string design_report_json(const DesignInput& input, const DesignOutcome& outcome) {
  const DesignResult& result = outcome.result;
  const PreparedTarget& target = input.target;
  JsonWriter json;
  json.begin_object()
      .value("converged", result.converged)
      .value("stop_reason", design_stop_name(result.stop))
      .value("method", design_method_name(result.method))
      .value("avg_error_mm", result.avg_error_mm)
      .value("max_error_mm", result.max_error_mm)
      .value("avg_error_rel", result.avg_error_rel)
      .value("max_error_rel", result.max_error_rel)
      .value("bbox_diag_mm", result.bbox_diag_mm)
      .value("pressure_kpa", result.pressure_kpa)
      .value("volume_ratio", result.volume_ratio)
      .value("iterations", result.iterations)
      .value("time_s", result.time_s)
      .value("vertices", result.rest.vertex_count())
      .value("faces", result.rest.face_count());
  json.begin_array("active_terms");
  for (const std::string& term : result.active_terms) json.value("", term);
  json.end_array();
  // Ratios of values that exist; null otherwise (no baseline, no design, or a design with zero error).
  const auto ratio = [](const std::optional<double>& a, const std::optional<double>& b) -> std::optional<double> {
    if (!a || !b || !(*b > 0.0)) return std::nullopt;
    return *a / *b;
  };
  json.value("baseline_avg_error_mm", result.baseline_avg_error_mm)
      .value("baseline_max_error_mm", result.baseline_max_error_mm)
      .value("baseline_avg_error_rel", ratio(result.baseline_avg_error_mm, result.bbox_diag_mm))
      .value("improvement_over_baseline", ratio(result.baseline_avg_error_mm, result.avg_error_mm))
      .value("distance_energy", result.distance_energy)
      .value("residual_norm", result.residual_norm)
      .value("material", material_spec(input.material))
      .value("material_name", input.material.name)
      .value("thickness_mm", input.parameters.thickness_mm)
      .value("start_scale", input.start_scale)
      .value("max_time_s", input.parameters.max_time_s)
      .value("cancelled", outcome.cancelled)
      .value("message", result.message);
  if (result.resumed_from_iteration) json.value("resumed_from_iteration", *result.resumed_from_iteration);

  json.begin_object("preparation")
      .value("summary", target.summary)
      .value("scale_factor", target.scale_factor)
      .value("reoriented", target.reoriented)
      .value("unreferenced_vertices_removed", target.unreferenced_vertices_removed)
      .value("remeshed", target.remeshed)
      .value("vertices_before", target.vertices_before)
      .value("vertices_after", target.vertices_after)
      .value("faces_before", target.faces_before)
      .value("faces_after", target.faces_after)
      .value("min_angle_before_deg", target.min_angle_before_deg)
      .value("min_angle_after_deg", target.min_angle_after_deg)
      .value("target_edge_length_mm", target.target_edge_length_mm)
      .value("bbox_diag_mm", target.bbox_diag_mm)
      .value("volume_mm3", target.volume_mm3)
      .value("self_intersecting", target.self_intersecting)
      .end_object();

  json.begin_object("nozzle").value("requested", input.parameters.nozzle);
  if (input.nozzle) {
    json.value("center_vertex", input.nozzle->center_vertex)
        .value("radius_mm", input.nozzle->radius_mm)
        .value("fixed_vertices", static_cast<int>(input.nozzle->vertices.size()));
  } else {
    json.value("fixed_vertices", 0);
  }
  json.end_object();

  if (outcome.mold) {
    json.begin_object("mold")
        .value("nozzle_vertex", outcome.mold->nozzle_vertex)
        .value("tube_radius_mm", outcome.mold->tube_radius_mm)
        .value("tube_length_mm", outcome.mold->tube_length_mm)
        .end_object();
  } else {
    json.value("mold_problem", outcome.mold_problem);
  }

  if (outcome.tolerance) {
    json.begin_object("tolerance")
        .value("samples", input.parameters.tolerance_samples)
        .value("seed", static_cast<long long>(TOLERANCE_SEED))
        .value("control", "volume_ratio");
    json.begin_array("levels");
    for (const ThicknessToleranceLevel& level : outcome.tolerance->levels) {
      json.begin_object()
          .value("perturbation", level.perturbation)
          .value("mean_deviation_mm", level.mean_deviation_mm)
          .value("max_deviation_mm", level.max_deviation_mm)
          .value("samples", level.samples)
          .value("failed_samples", level.failed_samples)
          .end_object();
    }
    json.end_array().end_object();
  }

  // Parallel arrays keep the log compact; convergence_csv() writes the same numbers as CSV.
  json.begin_object("convergence");
  const auto column = [&](const char* key, auto field) {
    json.begin_array(key);
    for (const ConvergenceSample& sample : result.log) json.value("", field(sample));
    json.end_array();
  };
  column("time_s", [](const ConvergenceSample& s) { return s.time_s; });
  column("iteration", [](const ConvergenceSample& s) { return s.iteration; });
  column("avg_error_mm", [](const ConvergenceSample& s) { return s.avg_error_mm; });
  column("max_error_mm", [](const ConvergenceSample& s) { return s.max_error_mm; });
  column("residual_norm", [](const ConvergenceSample& s) { return s.residual_norm; });
  json.end_object();
  json.end_object();
  return json.str();
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
