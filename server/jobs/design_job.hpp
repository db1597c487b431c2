#pragma once
/// The design job without any transport: check the request, prepare the target, run the inverse design,
/// and find the mold. The service's design job kind runs designs through this layer and reports them
/// (service/job_reports); the CLI checks requests with design_parameters_problem.
#include <optional>
#include <string>
#include <vector>

#include "design/balloon_design.hpp"
#include "design/nozzle.hpp"
#include "design/target_preparation.hpp"
#include "design/thickness_tolerance.hpp"
#include "jobs/field_problem.hpp"
#include "jobs/simulate_job.hpp"
#include "material/material.hpp"
#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon::jobs {

/// Target resolution (vertices) when a request names none.
inline constexpr int DEFAULT_DESIGN_RESOLUTION = 4000;
/// Largest accepted --tolerance-samples (each sample is one inflation per level).
inline constexpr int MAX_TOLERANCE_SAMPLES = 100;
/// Seed of the thickness-tolerance perturbations: the same design gives the same tolerance figures.
inline constexpr unsigned TOLERANCE_SEED = 12345u;
/// Mold tube length as a fraction of the rest shape's bounding-box diagonal.
inline constexpr double MOLD_TUBE_LENGTH_FRACTION = 0.2;

/// What a user asked of a design, before any checking.
struct DesignParameters {
  double thickness_mm = DEFAULT_THICKNESS_MM;  ///< rest membrane thickness (mm), > 0
  double size_mm = 0.0;                        ///< scale the target to this bbox diagonal (mm); 0 keeps it
  int resolution = DEFAULT_DESIGN_RESOLUTION;  ///< remesh to about this many vertices; 0 never remeshes
  std::optional<double> scale;                 ///< start = target scaled by this (> 0)...
  std::optional<double> volume_ratio;          ///< ...or target volume / start volume (> 0); neither: 8
  std::string method;                          ///< "adjoint", "alm" or empty for the default
  std::string nozzle;                          ///< "X,Y,Z[,RADIUS]" (mm, target coordinates), "auto" or empty
  double max_time_s = 0.0;                     ///< optimizer wall-time budget (s); 0 none
  int tolerance_samples = 0;                   ///< thickness-tolerance samples per level; 0 skips the check
};

/// Empty when the parameters are usable, else one problem per bad field, named by its DesignJob field
/// ("thickness_mm", "scale" when scale and volume ratio are both given, "method", "nozzle", ...), each
/// with a one-line message (non-positive values, unknown method, unparsable nozzle, ...).
std::vector<FieldProblem> design_parameter_problems(const DesignParameters& parameters);

/// Where and how wide the mold's inflation tube is, on the rest shape.
struct MoldParameters {
  int nozzle_vertex = -1;       ///< rest vertex at the tube's centre
  double tube_radius_mm = 0.0;  ///< tube radius (mm)
  double tube_length_mm = 0.0;  ///< tube length beyond the surface (mm)
};

/// A design job whose inputs have all been checked: ready to run.
struct DesignInput {
  PreparedTarget target;          ///< the prepared target (mm) and what was done to it
  Material material;
  DesignParameters parameters;    ///< as given (checked)
  DesignMethod method = DesignMethod::Adjoint;
  double start_scale = 0.0;       ///< linear scale of the start: `scale`, or volume_ratio^(-1/3)
  std::optional<NozzleSelection> nozzle;  ///< selected on the prepared target when a nozzle was asked
};

/// Why the target `target_diagonal_mm` across (after `size_mm`) is too large (mesh_size_problem), or the
/// sheet too thick for the thin-sheet model (material/thin_sheet.hpp) on this design's start, the target
/// scaled down by `scale` or to 1 / `volume_ratio` of its volume; "" when neither. Cheap: the service asks
/// before remeshing, prepare_design again.
std::string design_size_problem(const DesignParameters& parameters, double target_diagonal_mm);

/// Checks the parameters and the material, prepares the target (prepare_target: size, resolution;
/// fails on bad meshes with a message starting "mesh: ") and selects the nozzle vertices.
/// Deterministic: the service calls it at submit time to check and again when the job runs.
Result<DesignInput> prepare_design(TriMesh target, const Material& material, const DesignParameters& parameters);

/// The finished run.
struct DesignOutcome {
  DesignResult result;
  std::optional<ThicknessTolerance> tolerance;  ///< when tolerance samples were asked and the run finished
  std::optional<MoldParameters> mold;           ///< the tube that builds a valid mold, if one was found
  std::optional<TriMesh> mold_mesh;             ///< the mold built with that tube (mm): what mold.stl holds
  std::string mold_problem;                     ///< why no mold could be built (empty when one was)
  bool cancelled = false;                       ///< the cancel token fired before the run finished
};

/// Runs the design (progress phases "design", then "tolerance"; the cancel token is checked between
/// iterations), the tolerance check if asked, and builds the mold (the server stores it with the result).
/// controls.max_time_s, when set, caps the optimizer's budget. Never throws for non-convergence: that is `result.converged == false`.
/// `resume`: the design's last checkpoint when it runs again after an interruption (see DesignOptions).
DesignOutcome run_design(const DesignInput& input, const RunControls& controls,
                         const std::optional<DesignCheckpoint>& resume = std::nullopt);

/// The mold for a rest shape (see build_mold) with the tube `mold`.
Result<TriMesh> design_mold(const TriMesh& rest, const MoldParameters& mold);

/// "avg error 0.12 mm (0.1% of 120 mm)", or "no design error (stop reason start_failed)" when there
/// is none: for logs and the COMPLETED event's message.
std::string design_error_summary(const DesignResult& result);

/// The convergence log as CSV: header `time_s,iteration,avg_error_mm,max_error_mm,residual_norm`,
/// one row per sample.
std::string convergence_csv(const std::vector<ConvergenceSample>& log);

}  // namespace balloon::jobs
