#include "jobs/simulate_job.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "material/thin_sheet.hpp"
#include "jobs/mesh_size.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon::jobs {
namespace {

std::string format_number(double value, const char* format = "%.6g") {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace

std::vector<FieldProblem> simulate_parameter_problems(const SimulateParameters& parameters) {
  std::vector<FieldProblem> problems;
  if (std::string thickness = thickness_problem(parameters.thickness_mm); !thickness.empty())
    problems.push_back({"thickness_mm", std::move(thickness)});
  if (std::string size = size_mm_problem(parameters.size_mm); !size.empty()) problems.push_back({"size_mm", std::move(size)});
  const int controls = (parameters.pressure_kpa ? 1 : 0) + (parameters.volume_ratio ? 1 : 0) + (parameters.curve ? 1 : 0);
  if (controls > 1)
    problems.push_back({"pressure_kpa", parameters.curve ? "give a curve range or a single pressure or volume ratio, not both"
                                                         : "give either a pressure or a volume ratio, not both"});
  else if (controls == 0)
    problems.push_back({"pressure_kpa", "give a pressure (kPa) or a volume ratio (or a curve range)"});
  // A single run has the bounds of a curve's range (a ratio of 1e308 ran into the solver and came back as
  // "non-finite residual").
  else if (parameters.pressure_kpa && !(*parameters.pressure_kpa > 0.0 && *parameters.pressure_kpa <= MAX_CURVE_PRESSURE_KPA))
    problems.push_back({"pressure_kpa", "pressure must be a positive number of kPa up to " +
                                            format_number(MAX_CURVE_PRESSURE_KPA) + ", got " +
                                            format_number(*parameters.pressure_kpa)});
  else if (parameters.volume_ratio && !(*parameters.volume_ratio > 0.0 && *parameters.volume_ratio <= MAX_CURVE_VOLUME_RATIO))
    problems.push_back({"volume_ratio", "volume ratio must be a positive number up to " +
                                            format_number(MAX_CURVE_VOLUME_RATIO) + ", got " +
                                            format_number(*parameters.volume_ratio)});
  else if (parameters.curve) {
    const CurveParameters* curve = &*parameters.curve;
    // The range and the point count each by their own field: check the range with a valid count.
    const std::string range = curve_range_problem(curve->control, curve->from, curve->to, MIN_CURVE_POINTS);
    if (!range.empty())
      problems.push_back(
          {curve->control == InflationControl::Pressure ? "curve.pressure_range" : "curve.volume_ratio_range", range});
    if (curve->points < MIN_CURVE_POINTS || curve->points > MAX_CURVE_POINTS)
      problems.push_back({"curve.points", curve_range_problem(curve->control, 2.0, 3.0, curve->points)});
  }
  return problems;
}

Result<SimulateInput> prepare_simulate(TriMesh rest, const Material& material,
                                       const SimulateParameters& parameters) {
  if (const std::vector<FieldProblem> problems = simulate_parameter_problems(parameters); !problems.empty())
    return fail(problems.front().message);
  if (const std::string problem = material_problem(material); !problem.empty())
    return fail("material: " + problem);

  if (parameters.size_mm > 0.0 && scale_to_diagonal(rest.vertices, parameters.size_mm) == 0.0)
    return fail("mesh: it has no extent to scale to size_mm");
  Result<MeshCheckReport> report = validate_balloon_mesh(rest);
  if (!report) return fail("mesh: " + report.error());
  if (const std::string problem = mesh_size_problem(bounding_box_diagonal(rest.vertices)); !problem.empty())
    return fail("mesh: " + problem);
  if (const std::string problem = thin_sheet_problem(parameters.thickness_mm, bounding_box_diagonal(rest.vertices));
      !problem.empty())
    return fail("mesh: " + problem);

  SimulateInput input;
  input.flipped_orientation = report->flipped;
  input.rest = std::move(rest);
  input.material = material;
  input.thickness_mm = parameters.thickness_mm;
  input.curve = parameters.curve;
  if (parameters.pressure_kpa) {
    input.control = InflationControl::Pressure;
    input.pressure_kpa = *parameters.pressure_kpa;
  } else if (parameters.volume_ratio) {
    input.control = InflationControl::VolumeRatio;
    input.volume_ratio = *parameters.volume_ratio;
  }
  return input;
}

SimulateOutcome run_simulate(const SimulateInput& input, const RunControls& controls) {
  InflationOptions options;
  options.material = input.material;
  options.thickness_mm = input.thickness_mm;
  options.control = input.control;
  options.pressure_kpa = input.pressure_kpa;
  options.volume_ratio = input.volume_ratio;
  options.max_time_s = controls.max_time_s;
  options.progress = controls.progress;
  options.cancel = controls.cancel;

  SimulateOutcome outcome;
  outcome.result = inflate(input.rest, options);
  outcome.cancelled = controls.cancel != nullptr && controls.cancel->cancelled() && !outcome.result.converged;
  return outcome;
}

PressureVolumeCurve run_curve(const SimulateInput& input, const RunControls& controls) {
  PressureVolumeCurveOptions options;
  options.material = input.material;
  options.thickness_mm = input.thickness_mm;
  if (input.curve) {
    options.control = input.curve->control;
    options.from = input.curve->from;
    options.to = input.curve->to;
    options.points = input.curve->points;
  }
  options.max_time_s = controls.max_time_s;
  options.progress = controls.progress;
  options.cancel = controls.cancel;
  return trace_pressure_volume_curve(input.rest, options);
}

}  // namespace balloon::jobs
