#include "jobs/simulate_job.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "mesh/mesh_checks.hpp"

namespace balloon::jobs {
namespace {

std::string format_number(double value, const char* format = "%.6g") {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

}  // namespace

std::string simulate_parameters_problem(const SimulateParameters& parameters) {
  if (!std::isfinite(parameters.thickness_mm) || parameters.thickness_mm <= 0.0)
    return "thickness must be a positive number of mm, got " + format_number(parameters.thickness_mm);
  if (parameters.pressure_kpa && parameters.volume_ratio)
    return "give either a pressure or a volume ratio, not both";
  if (!parameters.pressure_kpa && !parameters.volume_ratio)
    return "give a pressure (kPa) or a volume ratio";
  if (parameters.pressure_kpa && (!std::isfinite(*parameters.pressure_kpa) || *parameters.pressure_kpa <= 0.0))
    return "pressure must be a positive number of kPa, got " + format_number(*parameters.pressure_kpa);
  if (parameters.volume_ratio && (!std::isfinite(*parameters.volume_ratio) || *parameters.volume_ratio <= 0.0))
    return "volume ratio must be a positive number, got " + format_number(*parameters.volume_ratio);
  return "";
}

Result<SimulateInput> prepare_simulate(TriMesh rest, const Material& material,
                                       const SimulateParameters& parameters) {
  if (const std::string problem = simulate_parameters_problem(parameters); !problem.empty()) return fail(problem);
  if (const std::string problem = material_problem(material); !problem.empty())
    return fail("material: " + problem);

  Result<MeshCheckReport> report = validate_balloon_mesh(rest);
  if (!report) return fail("mesh: " + report.error());

  SimulateInput input;
  input.flipped_orientation = report->flipped;
  input.rest = std::move(rest);
  input.material = material;
  input.thickness_mm = parameters.thickness_mm;
  if (parameters.pressure_kpa) {
    input.control = InflationControl::Pressure;
    input.pressure_kpa = *parameters.pressure_kpa;
  } else {
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

}  // namespace balloon::jobs
