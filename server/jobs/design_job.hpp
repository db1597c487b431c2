#pragma once
/// The design job without any transport: check the request, prepare the target, run the inverse design,
/// and describe the outcome (report JSON, convergence log, mold). The CLI and the gRPC service both go
/// through this layer, so their checks, reports and molds agree.
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

/// Checks the parameters and the material, prepares the target (prepare_target: size, resolution;
/// fails on bad meshes with a message starting "mesh: ") and selects the nozzle vertices.
/// Deterministic: the service calls it at submit time to check and again when the job runs.
Result<DesignInput> prepare_design(TriMesh target, const Material& material, const DesignParameters& parameters);

/// The finished run.
struct DesignOutcome {
  DesignResult result;
  std::optional<ThicknessTolerance> tolerance;  ///< when tolerance samples were asked and the run finished
  std::optional<MoldParameters> mold;           ///< the tube that builds a valid mold, if one was found
  std::string mold_problem;                     ///< why no mold could be built (empty when one was)
  std::string report_json;                      ///< see design_report_json
  bool cancelled = false;                       ///< the cancel token fired before the run finished
};

/// Runs the design (progress phases "design", then "tolerance"; the cancel token is checked between
/// iterations), the tolerance check if asked, and finds the mold tube. controls.max_time_s, when set,
/// caps the optimizer's budget. Never throws for non-convergence: that is `result.converged == false`.
/// `resume`: the design's last checkpoint when it runs again after an interruption (see DesignOptions).
DesignOutcome run_design(const DesignInput& input, const RunControls& controls,
                         const std::optional<DesignCheckpoint>& resume = std::nullopt);

/// The mold for a rest shape (see build_mold): the service stores only meshes and the report, so the
/// client builds mold.stl from the rest mesh and the report's "mold" object through this same function.
Result<TriMesh> design_mold(const TriMesh& rest, const MoldParameters& mold);

/// mold.stl's mesh from a finished design as the store keeps it: `rest` is the job's rest mesh (mm) and
/// `report_json` its report (design_report_json), whose "mold" object names the tube. The one function
/// the CLI and the HTTP gateway both build the mold with. Fails when the report has no mold (the message
/// then carries the report's mold_problem), is not a design report, or the tube cannot be built.
Result<TriMesh> mold_from_report(const TriMesh& rest, const std::string& report_json);

/// "avg error 0.12 mm (0.1% of 120 mm)", or "no design error (stop reason start_failed)" when there
/// is none: for logs and the COMPLETED event's message.
std::string design_error_summary(const DesignResult& result);

/// One JSON object. Issue 4's keys: converged, method, avg_error_mm, max_error_mm, avg_error_rel,
/// max_error_rel, bbox_diag_mm, pressure_kpa, volume_ratio, iterations, time_s, vertices, active_terms,
/// baseline_avg_error_mm, baseline_max_error_mm; also faces, material, material_name, thickness_mm,
/// distance_energy, residual_norm (N), message, preparation {...}, nozzle {...}, mold {nozzle_vertex,
/// tube_radius_mm, tube_length_mm} or mold_problem, tolerance {...} when asked, and convergence
/// {time_s, iteration, avg_error_mm, max_error_mm, residual_norm} as parallel arrays.
std::string design_report_json(const DesignInput& input, const DesignOutcome& outcome);

/// The convergence log as CSV: header `time_s,iteration,avg_error_mm,max_error_mm,residual_norm`,
/// one row per sample.
std::string convergence_csv(const std::vector<ConvergenceSample>& log);

}  // namespace balloon::jobs
