#pragma once
/// Static inflation of a closed membrane: the equilibrium shape under a given pressure, or at a given
/// enclosed volume with the pressure as an unknown (volume control passes pressure maxima).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "material/material.hpp"
#include "material/pressure_fall_band.hpp"
#include "mesh/tri_mesh.hpp"
#include "progress.hpp"

namespace balloon {

enum class InflationControl { Pressure, VolumeRatio };

/// Whether the membrane carries the sheet's bending stiffness (see InflationOptions::bending).
enum class BendingUse { Off, On, Auto };

struct InflationOptions {
  Material material;
  double thickness_mm = 0.5;                 ///< rest membrane thickness h (mm), uniform
  std::vector<double> element_thickness_mm;  ///< optional per-triangle thickness (mm); overrides thickness_mm
  InflationControl control = InflationControl::VolumeRatio;
  double pressure_kpa = 0.0;                 ///< target pressure (kPa) under pressure control
  double volume_ratio = 1.0;                 ///< target V / V_rest under volume control
  std::vector<int> fixed_vertices;           ///< vertices held at their rest positions (clamped rim, nozzle)
  double residual_tolerance = 1e-8;          ///< stop when |f| <= tol * (p * A_rest), relative force residual
  int max_newton_iterations = 200;           ///< over all load steps
  double max_time_s = 0.0;                   ///< wall-time budget (s); 0 means none
  /// Pipkin's tension-field relaxation (fem/membrane_element.hpp): compressed triangles wrinkle instead
  /// of carrying compressive stress; it changes nothing where the membrane is taut. Off by default:
  /// on bench_robustness it cures some shapes and slows others, because slack regions are mechanisms
  /// (zero stiffness) near zero pressure (README, "Robustness").
  bool tension_field = false;
  /// The sheet's bending stiffness D = G h^3 / 3 as discrete-shell hinges (fem/hinge_bending.hpp): gives
  /// compressed regions a stable folded state instead of ever finer wrinkles. `Auto` (the default)
  /// inflates as a pure membrane and switches bending on only when a volume step fails to converge, or
  /// (inflate() only) tries again with it once when the membrane's equilibrium passes through itself
  /// (InflationResult::bending says whether it was on at the end).
  BendingUse bending = BendingUse::Auto;
  /// A converged shape whose surface passes through itself (while the rest surface does not) is no
  /// physical equilibrium: the walls would touch first, and this model has no contact. Reported as
  /// InflationStop::PassesThroughItself. Costs two CGAL self-intersection tests (~10 ms per 10k faces).
  /// inflate() also checks the equilibria its path reached by a hard step (more than 20 Newton steps) or
  /// failed to leave, and ends there when one passes through itself (the result says "on the way to").
  bool reject_self_intersection = true;
  /// NewtonSettings::shift_restart for this path: 1/2, for long paths through snap-throughs and wrinkles
  /// (bench_robustness: 24 -> 19 failures of 432 against 1/4). The design's start passes its own 1/4.
  double sqp_shift_restart = 0.5;
  /// NewtonSettings::shift_after_cut_short for this path; the design's start passes its own (off).
  bool sqp_shift_after_cut_short = true;
  ProgressCallback progress;                 ///< optional
  /// Seconds between the "newton" progress events within a step (each Newton iteration's residual and
  /// pressure, no shape), so a long step shows it is alive; the first comes after as long. "inflate"
  /// events come once per volume or pressure step reached, with the shape.
  double newton_progress_interval_s = 1.0;
  const CancelToken* cancel = nullptr;       ///< optional
};

/// Why an inflation stopped.
enum class InflationStop {
  Converged,             ///< an equilibrium at the requested volume or pressure (NewtonSettings' test)
  InvalidInput,          ///< the options or the rest mesh were rejected before any work
  AboveMaximumPressure,  ///< pressure control asked for more than the balloon's pressure maximum
  NoEquilibrium,         ///< the load path could not be continued (the message says where and why)
  PassesThroughItself,   ///< the equilibrium found would pass through itself: the walls touch before it
  Cancelled,
  TimeLimit,
};

/// One word per stop reason ("converged", "above_max_pressure", ...), for reports.
const char* inflation_stop_word(InflationStop stop);

/// A pressure maximum or minimum that a pressure-controlled path passed on its way to the target: the
/// vertex of the parabola through the volume path's three states around the turn, in log(V / V_rest).
/// Held at a pressure just above a maximum, a balloon snaps to the larger shape at that pressure.
struct PassedExtremum {
  bool maximum = true;        ///< else a minimum
  double volume_ratio = 0.0;  ///< V / V_rest
  double pressure_kpa = 0.0;
};

struct InflationResult {
  bool converged = false;
  InflationStop stop = InflationStop::NoEquilibrium;
  std::string message;            ///< why it stopped; names the failure when not converged
  Positions deformed;             ///< #V by 3 equilibrium positions (mm)
  double pressure_kpa = 0.0;      ///< equilibrium pressure (kPa)
  double volume_mm3 = 0.0;        ///< enclosed volume of the deformed mesh (mm^3)
  double rest_volume_mm3 = 0.0;   ///< enclosed volume of the rest mesh (mm^3)
  double volume_ratio = 0.0;      ///< volume_mm3 / rest_volume_mm3
  double mean_stretch = 0.0;      ///< sqrt(A / A_rest), area-mean extension ratio
  double max_stretch = 0.0;       ///< largest principal stretch over all triangles
  double residual_norm = 0.0;     ///< |f_mem + f_p| over all free coordinates (N)
  int unstable_modes = 0;         ///< volume control: unstable directions of the equilibrium (0 = stable)
  int wrinkled_elements = 0;      ///< triangles the tension field relaxed at the end (wrinkled or slack); 0 when it is off
  bool bending = false;           ///< the sheet's bending stiffness was on at the end (see InflationOptions::bending)
  /// Cap slivers (smallest angle below CAP_SLIVER_ANGLE_DEG = 0.1 degree, mesh/cap_sliver_flips.hpp)
  /// whose edge the simulation flipped: the vertices are the caller's, only those pairs' diagonals differ
  /// (the surface moves by at most a cap's height).
  int flipped_cap_slivers = 0;
  /// Pressure control: the maxima and minima of the pressure along the volume path from the last
  /// equilibrium to this one, in path order (none under volume control, which reports every state it asks for).
  std::vector<PassedExtremum> passed_extrema;
  /// Where the rubber's sphere pressure falls as it stretches (material/pressure_fall_band.hpp); none
  /// when it never does. Set by inflate(), not by InflationPath.
  std::optional<PressureFallBand> pressure_fall;
  /// The share (0..1) of the equilibrium's area stretched into that band (material/pressure_fall_share.hpp);
  /// none unless converged with a band.
  std::optional<double> pressure_fall_area_share;
  int newton_iterations = 0;
  int factorizations = 0;
  int load_steps = 0;
  double time_s = 0.0;
};

/// Inflates `rest` (a closed, outward-oriented mesh in mm). `initial_guess` (#V by 3, mm) warm-starts
/// the solve; without it the rest shape scaled about its centroid is used.
InflationResult inflate(const TriMesh& rest, const InflationOptions& options,
                        const Positions* initial_guess = nullptr);

/// One inflation path followed target after target: each advance starts from the last equilibrium and
/// reuses the model, the sparsity pattern and CHOLMOD's analysis (the pressure-volume curve's path).
class InflationPath {
 public:
  /// `options` as for inflate(); its control and targets are ignored (each advance names its own), and so is
  /// reject_self_intersection (no point of the path is judged for passing through itself).
  /// `initial_guess` as for inflate().
  InflationPath(const TriMesh& rest, const InflationOptions& options, const Positions* initial_guess = nullptr);
  ~InflationPath();
  InflationPath(const InflationPath&) = delete;
  InflationPath& operator=(const InflationPath&) = delete;

  /// Continues to V / V_rest = target (VolumeRatio) or to the pressure target (kPa, Pressure). Counters
  /// and time in the result are totals since construction. Not converged: the state stays at the last
  /// equilibrium the volume path reached, and the result says why (InvalidInput for rejected options).
  InflationResult advance(InflationControl control, double target);

  /// Unstable directions of the last state under pressure control: negative eigenvalues of the
  /// stiffness Hess(W - p V) over the free coordinates (0 = stable); -1 when it is singular. Under volume
  /// control the result's unstable_modes counts them for the bordered (volume-constrained) system.
  int pressure_unstable_modes();

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

}  // namespace balloon
