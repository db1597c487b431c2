#pragma once
/// One design run's shared state and the steps both optimizers take: the start shape, its inflation by
/// volume steps (a continuation in the inflated volume), resuming from a checkpoint (a continuation in the
/// rest shape), trial equilibria, the progress log, the best design seen and the result. The optimizers
/// (reduced_space_design.hpp, augmented_lagrangian_design.hpp) move the rest shape; the driver keeps the
/// current equilibrium (x, pressure) of it.
#include <Eigen/Core>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "design/adjoint_sensitivity.hpp"
#include "design/background_inflation.hpp"
#include "design/balloon_design.hpp"
#include "design/design_objective.hpp"
#include "fem/balloon_model.hpp"
#include "solve/equilibrium_solver.hpp"

namespace balloon {

constexpr double MPA_PER_KPA = 1e-3;

/// The design's start rest shape: the target scaled about its centroid (DesignOptions::scale, or to
/// 1/volume_ratio of its volume), or the given initial rest shape rescaled to that volume.
TriMesh design_start_shape(const TriMesh& target, const DesignOptions& options);

/// Steady-clock seconds (the clock of NewtonSettings::deadline_s).
double design_clock_s();

/// Whether BALLOON_DEBUG_DESIGN asks for the design's trace on stderr (read once).
bool design_debug();

/// Sets the stop reason and its sentence.
void stop_with(DesignResult& result, DesignStop stop, std::string message);

class DesignDriver {
 public:
  /// `target` and `options` must outlive the driver (options' callbacks and cancel token included).
  DesignDriver(const TriMesh& target, const DesignOptions& options);
  DesignDriver(const DesignDriver&) = delete;
  DesignDriver& operator=(const DesignDriver&) = delete;

  const TriMesh& target() const { return m_target; }
  const DesignOptions& options() const { return m_options; }
  /// The start rest shape (the downscaled target, or the given initial rest shape rescaled).
  const TriMesh& start() const { return m_rest_mesh; }
  fem::BalloonModel& model() { return m_model; }
  EquilibriumSolver& solver() { return m_solver; }
  /// dx/drest at the current equilibrium: the gradient and the predictor.
  AdjointSensitivity& sensitivity() { return m_sensitivity; }
  DesignObjective& objective() { return m_objective; }
  const NewtonSettings& settings() const { return m_settings; }
  /// 3#V flags: false for rest coordinates the nozzle holds.
  const std::vector<bool>& rest_free() const { return m_rest_free; }
  double target_volume() const { return m_target_volume; }
  double start_time() const { return m_start; }

  /// The current inflated shape (3#V, mm, target frame), its pressure (MPa) and the last Newton report.
  Eigen::VectorXd& x() { return m_x; }
  double& pressure() { return m_pressure; }
  NewtonReport& last_report() { return m_last_report; }

  /// A result for `method` with the target's diagonal and the shared active terms.
  DesignResult begin(DesignMethod method) const;
  /// Inflates the start `rest` to the target's volume (by volume steps when one step is too far), places
  /// it on the target, and records the baseline as iteration 0. False (result stop set) when it fails.
  bool inflate_start(const Eigen::VectorXd& rest, DesignResult& result);
  /// Brings a checkpoint's rest shape (at this design's rest volume) to equilibrium from the inflated
  /// start, through rest shapes blended from the start's, or, where that path wrinkles, inflated on its
  /// own like the start (a term that switched on, e.g. sheet_bending, goes into `result`). On success
  /// `rest`, x and pressure are the checkpoint's; otherwise nothing changes.
  bool resume_from(const DesignCheckpoint& checkpoint, Eigen::VectorXd& rest, DesignResult& result);
  /// After a trial that crept through wrinkles with no stable membrane state (creeping_through_wrinkles):
  /// switches the sheet's bending on for the rest of the design (term sheet_bending) and brings the
  /// current `rest` to equilibrium with it from x. False, with bending off again and x unchanged, when it
  /// is on already, the method is alm (membrane-only derivatives) or that equilibrium is not found.
  bool switch_bending_on(const Eigen::VectorXd& rest, DesignResult& result);
  /// Volume-controlled equilibrium of `rest` from (x, p) with a short Newton budget; false when it does
  /// not converge (last_report() says why).
  bool equilibrium(const Eigen::VectorXd& rest, Eigen::VectorXd& x, double& pressure);
  /// Takes the current equilibrium of `rest`, accepted where Newton stagnated within a few tolerances,
  /// on to the force tolerance itself (SETTLE_NEWTON_ITERATIONS steps): x and pressure are replaced
  /// where it gets there; false, with nothing changed, where it does not.
  bool settle(const Eigen::VectorXd& rest);
  /// Whether a trial's start (x, pressure) with `rest` is worth Newton steps: false where its residual is
  /// non-finite or beyond 1e10 times the force scale (PREDICTOR_RESIDUAL_LIMIT: a predictor carried past the
  /// linear range, where a stiffening rubber's forces explode).
  bool trial_start_in_range(const Eigen::VectorXd& rest, const Eigen::VectorXd& x, double pressure);
  /// Starts inflating `rest`, the rest shape of `iteration`, from rest as `balloon simulate` does, on a
  /// thread of its own (a check still running is abandoned), and notes the current equilibrium, to which
  /// take_pending_shape_from_rest compares the shape reached.
  void start_shape_from_rest(const Eigen::VectorXd& rest, int iteration);
  /// Whether a check started by start_shape_from_rest awaits take_pending_shape_from_rest.
  bool shape_from_rest_pending() const { return m_from_rest.running(); }
  /// Waits for the check start_shape_from_rest started. Where it reached another shape than the
  /// equilibrium noted then (farther from it than that equilibrium's error), the design goes back to the
  /// check's rest shape and goes on from the shape reached, placed on the target: `rest`, x and pressure
  /// are replaced and the best design seen is forgotten. True when it switched; false with nothing
  /// changed otherwise (no check pending, the check did not converge, or it reached the design's shape).
  /// Either way a shape reached is a candidate for the result's closest_from_rest. Before it switches,
  /// the iterates recorded between the previous check and this one are inflated from rest too, earliest
  /// first, up to the first that reaches another shape than its design's: candidates on the design's
  /// branch, which the check of the growth alone had passed over.
  bool take_pending_shape_from_rest(Eigen::VectorXd& rest);
  /// Whether the last Newton solve stopped on the cancel token or the deadline.
  bool stopped() const;

  /// Restores the rest volume after a step, moving only free vertices along the volume gradient.
  Eigen::VectorXd keep_rest_volume(Eigen::VectorXd rest, double volume) const;
  double rest_volume(const Eigen::VectorXd& rest) const;

  /// Appends a log row and sends a progress event for the current equilibrium of `rest`.
  void record(DesignResult& result, int iteration, const SurfaceDistanceStats& stats, const Eigen::VectorXd& rest);
  /// Keeps (rest, x, pressure) when `avg_error` is the smallest seen.
  void remember_if_best(const Eigen::VectorXd& rest, double avg_error);
  /// Keeps `rest` as the result's closest_from_rest when the shape it reached from rest, `reached`, is the
  /// closest to the target seen and does not pass through itself.
  void remember_if_closest_from_rest(const Eigen::VectorXd& rest, const Positions& reached, int iteration);
  /// Goes back to the best design seen when its average surface error is below the current one's; true
  /// when it did.
  bool restore_best(Eigen::VectorXd& rest);
  /// Goes back to the best design seen whatever the current shape's error (it is no equilibrium); false
  /// when none was recorded.
  bool restore_best_equilibrium(Eigen::VectorXd& rest);
  /// Whether the returned shape is an equilibrium (alm: whether its final re-inflation converged).
  void set_final_equilibrium(bool converged) { m_final_equilibrium = converged; }
  /// The result's shapes and errors. Without an inflated start (start_failed, or stopped before it)
  /// there is no design: the errors stay empty, the rest shape is the start, nothing is called converged.
  DesignResult& finish(DesignResult& result, const Eigen::VectorXd& rest);

  /// With BALLOON_DEBUG_DESIGN set, prints the time since the start after `what` (stderr).
  void debug_time(const char* what) const;

 private:
  /// The start's inflation to the target's volume by the forward solver's volume path (solve/inflation).
  /// Where that needed the sheet's bending stiffness, the design keeps it on (adjoint method; listed as
  /// the active term "sheet_bending").
  bool inflate_start_to_target_volume(const Eigen::VectorXd& rest, DesignResult& result);
  /// Volume control from `rest` to the target's volume with the model's material and thickness, to the
  /// design's tolerance, within the design's deadline: what the start and the checks from rest share.
  InflationOptions inflation_from_rest(const Eigen::VectorXd& rest) const;
  /// The sheet's bending on or off in the model, and the solver's pattern to match.
  void set_bending(bool on);

  const TriMesh& m_target;
  const DesignOptions& m_options;
  double m_start;
  TriMesh m_rest_mesh;
  fem::BalloonModel m_model;
  EquilibriumSolver m_solver;
  AdjointSensitivity m_sensitivity;
  DesignObjective m_objective;
  double m_target_volume;
  std::vector<bool> m_rest_free;
  NewtonSettings m_settings;
  NewtonReport m_last_report;
  Eigen::VectorXd m_x;
  double m_pressure = 0.0;
  double m_best_error = std::numeric_limits<double>::infinity();
  Eigen::VectorXd m_best_rest, m_best_x;
  double m_best_pressure = 0.0;
  bool m_final_equilibrium = true;

  /// Inflates the iterates recorded before the pending check from rest, earliest first, until one reaches
  /// another shape than its design's (take_pending_shape_from_rest), within the budget.
  void check_iterates_before_the_pending_one();

  /// The check from rest running meanwhile: its rest shape, its iteration, and the design's equilibrium
  /// when it started.
  BackgroundInflation m_from_rest;
  Eigen::VectorXd m_from_rest_rest, m_from_rest_design_x;
  int m_from_rest_iteration = 0;
  std::optional<CheckedFromRest> m_closest_from_rest;
  /// A design iterate not checked from rest: its rest shape, its equilibrium and that one's error (mm).
  struct Iterate {
    int iteration = 0;
    Eigen::VectorXd rest, x;
    double avg_error_mm = 0.0;
  };
  std::deque<Iterate> m_since_check;   ///< recorded since the last check started (the latest few)
  std::vector<Iterate> m_before_check;  ///< recorded between the check before and the pending one
};

}  // namespace balloon
