#pragma once

/// Newton's method for the static equilibrium of a pressurised membrane, under pressure control
/// (minimise W(x) - p V(x)) or volume control (V(x) = V_target with p as the Lagrange multiplier,
/// which passes pressure maxima). A stateful object: the sparsity pattern and CHOLMOD's symbolic
/// analysis are built once and reused by every Newton step, load step and design iteration.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fem/assembly.hpp"
#include "fem/balloon_model.hpp"
#include "progress.hpp"
#include "solve/sparse_solver.hpp"

namespace balloon {

/// Why a Newton solve stopped.
enum class NewtonStop {
  Converged,         ///< the convergence test held (see NewtonSettings)
  IterationLimit,    ///< max_iterations reached without convergence
  LineSearchFailed,  ///< no step decreased the merit even with the strongest proximal damping
  NotFactorizable,   ///< the (shifted) stiffness could not be factorized
  NonFinite,         ///< the residual became NaN or infinite
  Cancelled,         ///< the cancel token fired
  TimeLimit,         ///< the deadline passed
  Slow,              ///< NewtonSettings::abandon_slow: the residual stopped falling fast enough
};

/// One word per stop reason ("converged", "iteration_limit", ...), for reports.
const char* newton_stop_word(NewtonStop stop);

/// Outcome of one Newton solve.
struct NewtonReport {
  bool converged = false;
  NewtonStop stop = NewtonStop::IterationLimit;
  std::string message;  ///< the stop reason as a sentence (unchanged CLI text)
  int iterations = 0;
  double residual_norm = 0.0;  ///< |grad W - p grad V| over the free coordinates (N)
  double volume_error = 0.0;   ///< V - V_target (mm^3), volume control only
  /// Volume control: directions along which the converged state is unstable (0 = a stable
  /// equilibrium, more = a saddle such as a symmetry-breaking mode), from the last exact factorization.
  int unstable_modes = 0;
  /// Volume control: exact factorizations of K during this solve, and how many of them were indefinite.
  /// A solve that fails while K keeps being indefinite is creeping through wrinkles: the membrane has no
  /// stable state there (InflationOptions::bending).
  int exact_factorizations = 0;
  int indefinite_factorizations = 0;
  /// Converged at the residual's rounding floor (N; see NewtonSettings), 0 when the tolerance itself held.
  double rounding_floor = 0.0;
  /// Converged by NewtonSettings::stagnation_tolerance_factor: |r| in force tolerances (above 1); 0 when
  /// the tolerance itself held.
  double stagnated_at = 0.0;
};

/// A failed solve that found the stiffness indefinite at most of its exact factorizations: compressed
/// regions wrinkling with no stable membrane state (as opposed to a slow but stable path).
inline bool creeping_through_wrinkles(const NewtonReport& report) {
  return !report.converged && 2 * report.indefinite_factorizations > report.exact_factorizations;
}

/// Convergence test: |r| <= relative_tolerance * F with the force scale F = |p| |grad V| + 1e-3 G h sqrt(A)
/// (G the small-strain shear modulus, h the mean thickness, A the rest area: a thousandth of the membrane
/// force a unit strain would cause), so the test keeps its meaning near zero pressure; under volume
/// control also |V - V_target| <= relative_tolerance * V_target.
///
/// Slivers (a fan of 0.04-degree triangles, say) can put the residual's own rounding error above that
/// tolerance: no step can lower it further. So once Newton stagnates (|r| above half the last |r|) with
/// the volume met, the rounding level of the residual is measured (residual_rounding) and a residual
/// within ROUNDING_MARGIN of it also counts as converged, reported as NewtonReport::rounding_floor, as
/// long as that floor is below MAX_ROUNDING_FLOOR * F (and the volume is met, to 1e-12 of it at most).
struct NewtonSettings {
  double relative_tolerance = 1e-8;  ///< see above
  int max_iterations = 30;
  const CancelToken* cancel = nullptr;
  double deadline_s = 0.0;  ///< absolute time (steady clock seconds) after which to stop; 0 = none
  /// Volume control: a shifted SQP step starts its search for the Levenberg shift from this fraction of
  /// the last one (then x10 until the KKT inertia is a constrained minimum's). A long path through snap-throughs
  /// and wrinkling (inflate()) restarts from 1/2: from 1/4 the shift cycled a decade above what the
  /// model needed and cut every step short (knot, femur). The design keeps 1/4, for its start too: its
  /// result depends on which of two equally converged starts it gets (spot with latex past its pressure
  /// maximum: 8.7x the baseline from the start solved with 1/4, 1.9x from the one solved with 1/2).
  double shift_restart = 0.25;
  /// Volume control: the SQP step after one cut short (more than two halvings) starts at the raised
  /// shift instead of trying the unshifted model first. inflate() turns it on (bench_robustness: 13 -> 9
  /// failures of 432; the femur at 20 mm, Neo-Hookean x8: 436 -> 108 Newton steps); the design keeps it
  /// off, for its start too: with it its latex corpus fell from 12/18 to 10/18 designs at 2x (teddy
  /// 4.6x -> 2.5x, stalled), silicone unchanged.
  bool shift_after_cut_short = false;
  /// Volume control: give up (NewtonStop::Slow) when, after four or more steps, the residual has not
  /// halved over the last two. For a caller that has a cheaper way on than a slow path to the end: the
  /// design's trials start a first-order step from their solution, so a trial that converges this slowly
  /// has stepped into a wrinkling or snapping region, and a shorter step costs less than finishing it.
  bool abandon_slow = false;
  /// Volume control: a solve that stagnates (abandon_slow's test, whether or not it abandons) with the
  /// volume met and |r| at most this many force tolerances counts as converged, reported as
  /// NewtonReport::stagnated_at (0 = never).
  /// Near a wrinkling bifurcation the stiffness is nearly singular, and exact steps wander a little above
  /// the tolerance without converging (the design's latex knot: 13 exact steps between 1e-5 and 9e-5 N
  /// against 9.5e-6 N, the volume met to 1e-4 mm^3; nothing non-smooth in that model).
  double stagnation_tolerance_factor = 0.0;
  /// Volume control: where SQP steps creep close to a saddle (see equilibrium_solver.cpp), the next ones
  /// use the exact Hessian, shifted, as their model instead of the projected membrane blocks. The design's
  /// trials turn it off (see DesignDriver::equilibrium).
  bool exact_hessian_near_saddles = true;
  /// Called at every Newton iteration that goes on (not at the converged one) with the iteration's index
  /// within this solve, its residual norm (N) and pressure (MPa): the progress of a long solve.
  std::function<void(int iteration, double residual_norm, double pressure_mpa)> on_iteration;
};

class EquilibriumSolver {
 public:
  /// `fixed_coordinate` (3#V) marks coordinates held at their current values.
  EquilibriumSolver(fem::BalloonModel& model, const std::vector<bool>& fixed_coordinate);

  fem::BalloonModel& model() { return m_model; }
  const fem::TriangleAssembly& assembly() const { return m_assembly; }

  /// Newton on W - p V at fixed pressure (MPa), from `x` (3#V, updated in place).
  NewtonReport solve_pressure(Eigen::VectorXd& x, double pressure_mpa, const NewtonSettings& settings);
  /// Newton on the KKT system of volume control, from (x, p) (updated in place).
  NewtonReport solve_volume(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                            const NewtonSettings& settings);

  /// Residual r = grad W - p grad V over all coordinates (N), zero at fixed coordinates.
  Eigen::VectorXd residual(const Eigen::VectorXd& x, double pressure_mpa) const;
  /// Force scale (N) against which residuals are judged.
  double force_scale(const Eigen::VectorXd& x, double pressure_mpa) const;
  /// Rounding level (N) of the free residual `r` at x: |r(x + t) - r(x)| for a rigid translation t of
  /// about the shape's size. The residual does not change under translation (W sees only edges, and grad V
  /// of a closed surface neither), so what does change is the error of evaluating it in floating point.
  double residual_rounding(const Eigen::VectorXd& x, double pressure_mpa, const Eigen::VectorXd& r) const;

  /// Factorizes the exact Hessian of W - p V at x (free coordinates). True if it is positive definite.
  bool factorize_at(const Eigen::VectorXd& x, double pressure_mpa);
  /// Factorizes the exact Hessian at x, indefinite allowed (LL^T, else LDL^T; straight to LDL^T once the
  /// exact Hessian was indefinite, since the LL^T attempt would only fail again). False if singular.
  bool factorize_exact(const Eigen::VectorXd& x, double pressure_mpa);
  /// K(x, p) w for full 3#V vectors (fixed coordinates ignored / zero), assembling K at x.
  Eigen::VectorXd stiffness_times(const Eigen::VectorXd& x, double pressure_mpa, const Eigen::VectorXd& w);
  /// Solves K y = b with the last factorization; b and y are full 3#V vectors (fixed entries ignored / zero).
  Eigen::VectorXd solve_with_factorization(const Eigen::VectorXd& b) const;

  int factorizations() const { return m_solver.factorizations(); }

  /// The held coordinates are a rigid support (rigid_support_coordinates), not physical supports. Exact
  /// Newton steps of volume control on a positive definite stiffness then drop their rigid-motion part:
  /// against six held coordinates a step carries whatever rotation brings them back to place, and a
  /// large linearised rotation adds a spurious second-order volume and energy that cut the line search
  /// short (the trefoil knot's design start, silicone: 265 -> 71 Newton steps with the second-order
  /// correction of constrained_descent). solve_volume then ends with the rigid motion that returns the
  /// held coordinates to their values on entry.
  void set_support_is_rigid(bool rigid);

  /// Rebuilds the sparsity pattern and forgets the step history after the model's hinges changed
  /// (BalloonModel::set_bending): the same fixed coordinates, a new symbolic analysis.
  void refresh_pattern();

 private:
  /// Factorizes K, or K + shift I with the smallest shift found that makes it positive definite.
  bool factorize_stiffness(const Eigen::VectorXd& x, double pressure_mpa);
  /// The convergence test's second half (see NewtonSettings): Newton stagnates and |r| is within its
  /// rounding level. Records the floor in `report`.
  bool at_rounding_floor(const Eigen::VectorXd& x, double pressure_mpa, const Eigen::VectorXd& r,
                         double previous_residual, double force_scale_n, NewtonReport& report) const;

  /// K^-1 r and K^-1 v with the last factorization, the two solves a volume-controlled step needs, made
  /// in one pass over the factors.
  struct KktSolves {
    Eigen::VectorXd of_residual, of_volume_gradient;
  };
  KktSolves solve_kkt(const Eigen::VectorXd& r, const Eigen::VectorXd& v) const;
  /// Negative eigenvalues of the bordered KKT matrix [K v; v^T 0] for the last LDL^T factorization of K
  /// (Haynsworth: the inertia of K plus the sign of -v^T K^-1 v), given `solved` = solve_kkt(r, v).
  int kkt_negative_eigenvalues(const Eigen::VectorXd& v, const KktSolves& solved) const;
  /// One SQP step for volume control with a positive definite model of the Hessian (projected membrane
  /// blocks, or with `exact_hessian` the exact one, plus a Levenberg shift), globalised on the augmented
  /// Lagrangian at the new multiplier. `settings` gives shift_restart and shift_after_cut_short.
  bool sqp_step(Eigen::VectorXd& x, double& pressure_mpa, double target_volume, const Eigen::VectorXd& v,
                const Eigen::VectorXd& r, double c, const NewtonSettings& settings, bool exact_hessian);
  /// KKT step of the factorized positive definite Hessian (model), line-searched on the augmented
  /// Lagrangian at the new multiplier or on a clear fall of the KKT residual. The number of step
  /// halvings the accepted step needed, or -1 if no step helped. `exact_model`: the factorization is
  /// the exact stiffness; only then, and only on a rigid support, does a step drop its rigid part and a
  /// rejected full step get its second-order correction. Measured: on the SQP's shifted model the first
  /// cost the femur at 200 mm (silicone x8) 478 Newton steps instead of 138 and the second made fandisk
  /// (latex x27) and the knot (Neo-Hookean x8) creep to the time limit; in the design's trials on its
  /// pinned support the correction cost latex designs iterations (teddy 5.1x -> 3.7x, spot 6.9x -> 6.0x).
  /// `solved` = solve_kkt(r, v) with that factorization.
  int constrained_descent(Eigen::VectorXd& x, double& pressure_mpa, double target_volume, const Eigen::VectorXd& v,
                          const Eigen::VectorXd& r, double c, const KktSolves& solved, bool exact_model);
  NewtonReport newton_volume(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                             const NewtonSettings& settings);
  /// After a solve on a rigid support: back to the held values, and the residual measured there.
  void return_to_support(Eigen::VectorXd& x, const Eigen::VectorXd& held, double pressure_mpa, NewtonReport& report) const;
  /// LDL^T of the exact stiffness assembled last; records whether it was indefinite.
  bool factorize_exact_ldlt();
  /// Exact stiffness for the volume-controlled KKT step, accepted when its inertia is right; fills
  /// `solved` = solve_kkt(r, v) when it was factorized.
  bool factorize_exact_for_volume(const Eigen::VectorXd& x, double pressure_mpa, const Eigen::VectorXd& v,
                                  const Eigen::VectorXd& r, KktSolves& solved);

  fem::BalloonModel& m_model;
  fem::TriangleAssembly m_assembly;
  SparseSolver m_solver;
  int m_skip_ldlt = 0;
  int m_exact_fails_left = 0;
  int m_last_unstable_modes = 0;
  double m_sqp_shift = 0.0;        ///< Levenberg shift of the last SQP step (N/mm)
  bool m_sqp_cut_short = false;    ///< the last SQP step was cut short (or failed): the next starts shifted
  int m_sqp_unshifted_steps = 0;        ///< consecutive unshifted SQP steps: close enough for the exact step
  bool m_last_step_exact = false;  ///< the last volume step was the exact one
  bool m_exact_indefinite = false;  ///< the last exact stiffness had negative pivots: skip the LL^T attempt
  bool m_sqp_indefinite = false;    ///< the last SQP model factorized had negative pivots: likewise
  double m_force_floor = 0.0;  ///< N, see force_scale()
  std::vector<int> m_support;  ///< the held coordinates, when they are a rigid support; else empty
};

}  // namespace balloon
