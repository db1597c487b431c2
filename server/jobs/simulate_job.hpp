#pragma once
/// The simulate job without any transport: check the request, inflate, and describe the outcome.
/// The service's simulate job kind runs simulations through this layer (and reports them: service/job_reports).
#include <optional>
#include <string>
#include <vector>

#include "jobs/field_problem.hpp"
#include "material/material.hpp"
#include "mesh/tri_mesh.hpp"
#include "progress.hpp"
#include "result.hpp"
#include "solve/inflation.hpp"
#include "solve/pressure_volume_curve.hpp"

namespace balloon::jobs {

/// Default rest membrane thickness (mm) when a request names none.
inline constexpr double DEFAULT_THICKNESS_MM = 0.5;

/// A pressure-volume curve request (SimulateJob.curve): `points` targets spaced geometrically over
/// from..to, V / V_rest under volume control or kPa under pressure control.
struct CurveParameters {
  InflationControl control = InflationControl::VolumeRatio;
  double from = 0.0;
  double to = 0.0;
  int points = 0;
};

/// How a user asked to load the membrane. Exactly one of pressure_kpa, volume_ratio and curve is set.
struct SimulateParameters {
  double thickness_mm = DEFAULT_THICKNESS_MM;  ///< rest thickness h (mm), > 0
  double size_mm = 0.0;                        ///< scale the rest mesh to this bbox diagonal (mm); 0 keeps it
  std::optional<double> pressure_kpa;          ///< pressure control (kPa), > 0
  std::optional<double> volume_ratio;          ///< volume control: target V / V_rest, > 0
  std::optional<CurveParameters> curve;        ///< the whole curve in one run
};

/// A simulate job whose inputs have all been checked: ready to run.
struct SimulateInput {
  TriMesh rest;                     ///< validated rest mesh (mm), oriented outwards
  bool flipped_orientation = false; ///< the mesh came oriented inwards and was flipped
  Material material;                ///< law and constants (MPa)
  double thickness_mm = DEFAULT_THICKNESS_MM;
  InflationControl control = InflationControl::VolumeRatio;
  double pressure_kpa = 0.0;        ///< pressure control target (kPa)
  double volume_ratio = 1.0;        ///< volume control target V / V_rest
  std::optional<CurveParameters> curve;  ///< set for a curve job (control and targets above unused)
};

/// Empty when the parameters are usable, else one problem per bad field, named by its SimulateJob field
/// ("thickness_mm", "size_mm", "pressure_kpa" when no or several controls are given, "volume_ratio",
/// "curve.volume_ratio_range" or "curve.pressure_range" for a bad range, "curve.points").
std::vector<FieldProblem> simulate_parameter_problems(const SimulateParameters& parameters);

/// Checks the parameters, the material constants and the mesh (closed, manifold, finite, ...), after
/// scaling it to `size_mm` when that is set; an inward-oriented mesh is flipped. The error names the
/// problem (and the face or vertex).
Result<SimulateInput> prepare_simulate(TriMesh rest, const Material& material,
                                       const SimulateParameters& parameters);

/// What the outside world gives a run: where progress goes, how to stop it, how long it may take.
struct RunControls {
  ProgressCallback progress;            ///< optional
  const CancelToken* cancel = nullptr;  ///< optional
  double max_time_s = 0.0;              ///< wall-time budget (s); 0 means none
};

/// The finished run (the service reports it: service/job_reports).
struct SimulateOutcome {
  InflationResult result;   ///< equilibrium (or the last iterate when not converged)
  bool cancelled = false;   ///< the cancel token fired before the run finished
};

/// Inflates a prepared job. Never throws for non-convergence: that is `result.converged == false`.
SimulateOutcome run_simulate(const SimulateInput& input, const RunControls& controls);

/// Follows the pressure-volume curve of a prepared curve job (input.curve set) in one path.
PressureVolumeCurve run_curve(const SimulateInput& input, const RunControls& controls);

}  // namespace balloon::jobs
