#include "design/multiresolution_design.hpp"

#include <algorithm>
#include <string>

#include "design/design_driver.hpp"
#include "design/surface_transfer.hpp"
#include "design/target_preparation.hpp"

namespace balloon {

namespace {

/// A coarse stage pays off only when it is clearly cheaper than the full-resolution design.
constexpr int MIN_REFINEMENT = 2;

/// The target remeshed to about `vertices`, or nothing when the remesher cannot keep it closed.
std::optional<TriMesh> coarse_target_of(const TriMesh& target, int vertices) {
  TargetPreparationOptions preparation;
  preparation.resolution = vertices;
  Result<PreparedTarget> prepared = prepare_target(target, preparation);
  if (!prepared.ok() || !prepared.value().remeshed) return std::nullopt;
  return prepared.value().mesh;
}

}  // namespace

bool runs_coarse_to_fine(const TriMesh& target, const DesignOptions& options) {
  return options.method == DesignMethod::Adjoint && options.coarse_vertices > 0 &&
         target.vertex_count() >= MIN_REFINEMENT * options.coarse_vertices && options.nozzle_vertices.empty() &&
         options.initial_rest.rows() == 0 && !options.resume && options.max_iterations >= 2;
}

Positions carry_rest_shape(const TriMesh& coarse_target, const Positions& coarse_start, const Positions& coarse_rest,
                           const TriMesh& fine_target, const Positions& fine_start) {
  const Positions change = coarse_rest - coarse_start;
  return fine_start + transfer_vertex_field(coarse_target, change, fine_target.vertices);
}

DesignResult design_coarse_to_fine(const TriMesh& target, const DesignOptions& options) {
  const double started = design_clock_s();
  const std::optional<TriMesh> coarse_target = coarse_target_of(target, options.coarse_vertices);
  DesignOptions fine_options = options;
  fine_options.coarse_vertices = 0;
  if (!coarse_target) return design_balloon(target, fine_options);

  DesignOptions coarse_options = fine_options;
  coarse_options.max_iterations = options.max_iterations - 1;  // at least one left for the full resolution
  if (options.max_time_s > 0) coarse_options.max_time_s = options.coarse_time_fraction * options.max_time_s;
  // The coarse stage reports its progress without shapes: they have the coarse target's vertices, and a
  // checkpoint taken from them would not fit the full-resolution design.
  if (options.progress) {
    coarse_options.progress = [&options](const ProgressEvent& event) {
      ProgressEvent coarse = event;
      coarse.phase = "coarse_" + event.phase;
      coarse.shape = nullptr;
      coarse.rest_shape = nullptr;
      options.progress(coarse);
    };
  }
  const DesignResult coarse = design_balloon(*coarse_target, coarse_options);
  CoarseStage stage;
  stage.vertices = coarse_target->vertex_count();
  stage.iterations = coarse.iterations;
  stage.time_s = design_clock_s() - started;
  stage.stop = coarse.stop;
  stage.avg_error_mm = coarse.avg_error_mm;

  const bool designed = coarse.iterations >= 1 && coarse.avg_error_mm && coarse.stop != DesignStop::Cancelled;
  if (designed) {
    const TriMesh coarse_start = design_start_shape(*coarse_target, fine_options);
    const TriMesh fine_start = design_start_shape(target, fine_options);
    fine_options.resume = DesignCheckpoint{
        carry_rest_shape(*coarse_target, coarse_start.vertices, coarse.rest.vertices, target, fine_start.vertices),
        coarse.iterations};
  }
  if (options.max_time_s > 0) fine_options.max_time_s = std::max(1e-3, options.max_time_s - stage.time_s);
  if (options.progress) {
    fine_options.progress = [&options, offset = stage.time_s](const ProgressEvent& event) {
      ProgressEvent shifted = event;
      shifted.elapsed_s += offset;
      options.progress(shifted);
    };
  }
  DesignResult result = design_balloon(target, fine_options);
  stage.carried = designed && result.resumed_from_iteration.has_value();
  result.resumed_from_iteration.reset();  // a design carried from the coarse stage is not a resumed job
  for (ConvergenceSample& sample : result.log) sample.time_s += stage.time_s;
  result.time_s += stage.time_s;
  result.coarse_stage = stage;
  return result;
}

}  // namespace balloon
