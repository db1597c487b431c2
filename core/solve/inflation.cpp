#include "solve/inflation.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "material/pressure_fall_share.hpp"
#include "material/thin_sheet.hpp"
#include "mesh/cap_sliver_flips.hpp"
#include "mesh/centred_frame.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/inflation_run.hpp"
#include "solve/quantity_text.hpp"

namespace balloon {
namespace {

std::string options_problem(const TriMesh& rest, const InflationOptions& options) {
  if (rest.vertex_count() < 3 || rest.face_count() < 1) return "the rest mesh is empty";
  if (!rest.vertices.allFinite()) return "the rest mesh has non-finite coordinates";
  if (auto problem = material_problem(options.material); !problem.empty()) return problem;
  if (options.element_thickness_mm.empty()) {
    if (auto problem = thickness_problem(options.thickness_mm); !problem.empty()) return problem;
  } else {
    if (static_cast<int>(options.element_thickness_mm.size()) != rest.face_count())
      return "per-triangle thickness needs one value per triangle";
    for (double h : options.element_thickness_mm)
      if (auto problem = thickness_problem(h); !problem.empty()) return "per-triangle " + problem;
  }
  const double thickest = options.element_thickness_mm.empty()
                              ? options.thickness_mm
                              : *std::max_element(options.element_thickness_mm.begin(), options.element_thickness_mm.end());
  if (auto problem = thin_sheet_problem(thickest, bounding_box_diagonal(rest.vertices)); !problem.empty()) return problem;
  if (options.control == InflationControl::VolumeRatio &&
      (!(options.volume_ratio > 0.0) || !std::isfinite(options.volume_ratio)))
    return "volume ratio must be a positive number";
  if (options.control == InflationControl::Pressure &&
      (!(options.pressure_kpa > 0.0) || !std::isfinite(options.pressure_kpa)))
    return "pressure must be a positive number (kPa)";
  for (int v : options.fixed_vertices)
    if (v < 0 || v >= rest.vertex_count()) return "fixed vertex " + std::to_string(v) + " does not exist";
  return "";
}

/// The mesh and options a run simulates: the rest mesh moved to its centred frame (positions go back to
/// the caller's frame through `frame`) with its cap slivers flipped away (same vertices), a flipped pair
/// taking the mean of its two thicknesses.
struct SimulationMesh {
  CentredFrame frame;
  TriMesh rest;
  InflationOptions options;
  int flipped_cap_slivers = 0;
};

SimulationMesh simulation_mesh(const TriMesh& rest, const InflationOptions& options) {
  CapSliverFlips flips = flip_cap_slivers(rest);
  const CentredFrame frame(rest.vertices);
  SimulationMesh simulated{frame, TriMesh{frame.centred(rest.vertices), std::move(flips.faces)}, options,
                           static_cast<int>(flips.flipped_pairs.size())};
  std::vector<double>& thickness = simulated.options.element_thickness_mm;
  if (!thickness.empty())
    for (const auto& [f, g] : flips.flipped_pairs)
      thickness[static_cast<size_t>(f)] = thickness[static_cast<size_t>(g)] =
          0.5 * (thickness[static_cast<size_t>(f)] + thickness[static_cast<size_t>(g)]);
  return simulated;
}

/// A membrane's equilibrium can pass through itself by a fold of its wrinkles (the dinosaur with latex at
/// x27: its limbs), which the sheet's bending smooths out: tried once more, from the start, with bending
/// on and the budget left. A converged bent result replaces `result` (the counters add up either way);
/// otherwise returns why it did not.
std::string retry_with_bending(const TriMesh& rest, const InflationOptions& options, const Positions* initial_guess,
                               InflationResult& result) {
  if (options.max_time_s > 0.0 && result.time_s >= options.max_time_s) return "no time left";
  InflationOptions bent = options;
  bent.bending = BendingUse::On;
  if (options.max_time_s > 0.0) bent.max_time_s = options.max_time_s - result.time_s;
  InflationResult second = InflationRun(rest, bent).run(initial_guess);
  InflationResult& kept = second.converged ? second : result;
  kept.newton_iterations = result.newton_iterations + second.newton_iterations;
  kept.factorizations = result.factorizations + second.factorizations;
  kept.load_steps = result.load_steps + second.load_steps;
  kept.time_s = result.time_s + second.time_s;
  if (!second.converged) return second.message;
  result = std::move(second);
  return "";
}

}  // namespace

const char* inflation_stop_word(InflationStop stop) {
  switch (stop) {
    case InflationStop::Converged: return "converged";
    case InflationStop::InvalidInput: return "invalid_input";
    case InflationStop::AboveMaximumPressure: return "above_max_pressure";
    case InflationStop::NoEquilibrium: return "no_equilibrium";
    case InflationStop::PassesThroughItself: return "passes_through_itself";
    case InflationStop::Cancelled: return "cancelled";
    case InflationStop::TimeLimit: return "time_limit";
  }
  return "unknown";
}

struct InflationPath::Impl {
  Impl(const TriMesh& rest_mesh, const InflationOptions& path_options)
      : simulated{CentredFrame(rest_mesh.vertices), rest_mesh, path_options},
        problem(options_problem(rest_mesh, path_options)) {
    if (problem.empty()) {
      simulated = simulation_mesh(rest_mesh, path_options);
      run = std::make_unique<InflationRun>(simulated.rest, simulated.options);
      run->use_path_predictor();
    } else {
      simulated.rest.vertices = simulated.frame.centred(rest_mesh.vertices);  // as every position held here
    }
  }
  SimulationMesh simulated;  // the run keeps references to its mesh and options
  std::string problem;
  std::unique_ptr<InflationRun> run;
};

InflationPath::InflationPath(const TriMesh& rest, const InflationOptions& options, const Positions* initial_guess) {
  InflationOptions checked = options;
  // The targets are checked per advance; give options_problem harmless ones.
  checked.control = InflationControl::VolumeRatio;
  checked.volume_ratio = 1.0;
  // A curve reports every point it reaches; whether one passes through itself is not judged along it.
  checked.reject_self_intersection = false;
  m = std::make_unique<Impl>(rest, checked);
  if (!m->run) return;
  const Positions guess = initial_guess ? m->simulated.frame.centred(*initial_guess) : Positions();
  m->problem = m->run->start(initial_guess ? &guess : nullptr);
}

InflationPath::~InflationPath() = default;

InflationResult InflationPath::advance(InflationControl control, double target) {
  std::string problem = m->problem;
  if (problem.empty() && !(target > 0.0 && std::isfinite(target)))
    problem = control == InflationControl::Pressure ? "pressure must be a positive number (kPa)"
                                                    : "volume ratio must be a positive number";
  if (!problem.empty()) {
    InflationResult result;
    result.stop = InflationStop::InvalidInput;
    result.message = problem;
    result.deformed = m->simulated.frame.caller(m->simulated.rest.vertices);
    return result;
  }
  InflationResult result = m->run->advance(control, target);
  result.deformed = m->simulated.frame.caller(result.deformed);
  result.flipped_cap_slivers = m->simulated.flipped_cap_slivers;
  return result;
}

int InflationPath::pressure_unstable_modes() { return m->run ? m->run->pressure_unstable_modes() : -1; }

namespace {

/// inflate() on the simulated mesh: the run, then the answer's check against passing through itself.
InflationResult inflate_simulated(const SimulationMesh& simulated, const Positions* initial_guess) {
  const InflationOptions& options = simulated.options;
  InflationResult result = InflationRun(simulated.rest, options).run(initial_guess);
  const bool on_the_way = result.stop == InflationStop::PassesThroughItself;
  const bool ended_through_itself = result.converged && options.reject_self_intersection &&
                                    passes_through_itself(simulated.rest, result.deformed);
  if (!on_the_way && !ended_through_itself) return result;
  std::string bent_try;
  if (options.bending == BendingUse::Auto && !result.bending) {
    bent_try = retry_with_bending(simulated.rest, options, initial_guess, result);
    if (bent_try.empty() && !passes_through_itself(simulated.rest, result.deformed)) return result;
  }
  // Still on the way (the path failed beyond it) unless the bent try replaced it with its converged end.
  const bool short_of_target = !result.converged;
  result.converged = false;
  result.stop = InflationStop::PassesThroughItself;
  const std::string target = options.control == InflationControl::VolumeRatio
                                 ? "volume ratio " + format_number(options.volume_ratio)
                                 : format_kpa(options.pressure_kpa * MPA_PER_KPA);
  const std::string ratio = short_of_target && options.control == InflationControl::VolumeRatio
                                ? format_number_short_of(result.volume_ratio, options.volume_ratio)
                                : format_number(result.volume_ratio);
  result.message = std::string("no equilibrium: the ") + (result.bending ? "bent sheet's" : "membrane's") +
                   " equilibrium at volume ratio " + ratio + " (" +
                   format_kpa(result.pressure_kpa * MPA_PER_KPA) + ")" +
                   (short_of_target ? ", on the way to " + target + ", passes through itself; its walls touch there"
                                    : " passes through itself; its walls touch on the way there") +
                   ", and this model has no contact" +
                   (bent_try.empty() ? "" : "; tried again with the sheet's bending: " + bent_try);
  return result;
}

}  // namespace

InflationResult inflate(const TriMesh& rest, const InflationOptions& options, const Positions* initial_guess) {
  if (auto problem = options_problem(rest, options); !problem.empty()) {
    InflationResult result;
    result.stop = InflationStop::InvalidInput;
    result.message = problem;
    result.deformed = rest.vertices;
    return result;
  }
  const SimulationMesh simulated = simulation_mesh(rest, options);
  const Positions guess = initial_guess ? simulated.frame.centred(*initial_guess) : Positions();
  InflationResult result = inflate_simulated(simulated, initial_guess ? &guess : nullptr);
  result.deformed = simulated.frame.caller(result.deformed);
  result.flipped_cap_slivers = simulated.flipped_cap_slivers;
  result.pressure_fall = pressure_fall_band(options.material);
  if (result.converged && result.pressure_fall)
    result.pressure_fall_area_share = area_share_in_pressure_fall(rest, result.deformed, *result.pressure_fall);
  return result;
}

}  // namespace balloon
