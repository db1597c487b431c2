#pragma once
/// One inflation path, the engine behind inflate() and InflationPath (inflation.hpp): the volume path
/// that every control follows (volume steps, their resumes, the sheet's bending tried when a membrane
/// creeps, the check that the walls have not passed through each other), and pressure control on top
/// of it (pressure_control.cpp). Internal to solve/.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fem/assembly.hpp"
#include "fem/balloon_model.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/inflation.hpp"
#include "solve/sparse_solver.hpp"

namespace balloon {

/// The continuation state of an inflation: positions, pressure and the volume they satisfy.
struct PathPoint {
  Eigen::VectorXd x;      ///< 3 #V positions (mm), vertex after vertex
  double pressure = 0.0;  ///< MPa
  double volume = 0.0;    ///< mm^3
};

/// The inertia of the exact stiffness, for states EquilibriumSolver's positive definite test rejects:
/// its own assembly and LDL^T, so the solver's factorization and state are left alone.
class Inertia {
 public:
  /// `fixed`: 3 #V flags, true for the coordinates held (as the run's own solver has them).
  Inertia(const fem::BalloonModel& model, const std::vector<bool>& fixed);
  /// Negative eigenvalues of Hess(W - p V) at x; -1 when it is singular.
  int negative_eigenvalues(const fem::BalloonModel& model, const Eigen::VectorXd& x, double pressure_mpa);

 private:
  fem::TriangleAssembly m_assembly;
  SparseSolver m_solver;
};

/// The deformed surface intersects itself while the rest surface does not (a rest mesh that already
/// does says nothing about the inflation). A mesh CGAL cannot take is not judged.
bool passes_through_itself(const TriMesh& rest, const Positions& deformed);

/// A path from the rest shape (or a given first guess) through volume- or pressure-controlled targets;
/// holds references to its rest mesh and options, which must outlive it.
class InflationRun {
 public:
  InflationRun(const TriMesh& rest, const InflationOptions& options);
  // m_settings.on_iteration holds `this`.
  InflationRun(const InflationRun&) = delete;
  InflationRun& operator=(const InflationRun&) = delete;

  /// The whole run: start(initial_guess), then advance to the options' own target.
  InflationResult run(const Positions* initial_guess);

  /// Sets the path's first state: the rest shape, or `initial_guess` (#V by 3, mm). Empty when usable,
  /// else why not (the rest mesh encloses no volume).
  std::string start(const Positions* initial_guess);

  /// Continues the path from its current state to `target` (V / V_rest, or kPa under pressure control).
  /// A failed advance leaves the state at the last equilibrium the volume path reached.
  InflationResult advance(InflationControl control, double target);

  /// Continuation predictor for a path of many targets (InflationPath): the shape secant below, and the
  /// least-squares pressure of the predicted shape rather than the last pressure. Together they save
  /// about one Newton step per curve point.
  void use_path_predictor() { m_path_predictor = true; }

  /// Unstable directions of the current state under pressure control: the negative eigenvalues of the
  /// stiffness K = Hess(W - p V) over the free coordinates (0 when K is positive definite). One
  /// supernodal LL^T; the LDL^T for the inertia only when that fails. -1 when K is singular.
  int pressure_unstable_modes();

 private:
  /// The membrane (with the sheet's bending when BendingUse::On) of the rest mesh and options.
  static fem::BalloonModel make_model(const TriMesh& rest, const InflationOptions& options);
  /// Per-triangle rest thickness (mm): the options' own, or the uniform one for every triangle.
  static std::vector<double> thicknesses(const TriMesh& rest, const InflationOptions& options);
  /// 3 #V flags, true for the coordinates held: the user's fixed vertices, else a rigid support.
  static std::vector<bool> fixed_coordinates(const TriMesh& rest, const InflationOptions& options);

  bool has_user_fixed_vertices() const { return !m_options.fixed_vertices.empty(); }

  /// Least-squares pressure for a shape: the p minimising |grad W - p grad V|.
  double estimate_pressure(const Eigen::VectorXd& x) const;

  /// First guess at a new volume: scaled about the centroid for a free balloon (exact for a sphere),
  /// pushed along the vertex normals when vertices are held.
  Eigen::VectorXd predict(const Eigen::VectorXd& x, double target_volume) const;

  /// Path predictor: the scaled guess plus the change of shape beyond scaling over the last step, carried
  /// on in proportion to log V (a secant on the deviation from a sphere's self-similar growth). On a
  /// discrete sphere it takes the Newton step that the uneven stretch of the polyhedron would cost.
  void add_shape_secant(const PathPoint& state, double target_volume, Eigen::VectorXd& x) const;

  /// Phase "inflate": a volume step reached (`residual` in N), with its shape when `with_shape`.
  void report_progress(const PathPoint& state, double residual, bool with_shape);

  /// Phase "newton": the run's Newton iterations so far (the ones of this solve included), the current
  /// iterate's residual and pressure; at most one per InflationOptions::newton_progress_interval_s, no
  /// shape. (The first step of a 14k-vertex teddy with latex to x27 takes tens of seconds.)
  void report_newton_progress(int iteration, double residual_norm, double pressure_mpa);

  /// Where a volume step from `state` to `target_volume` starts: the scaled shape (and the path
  /// predictor's secant and pressure, when on).
  PathPoint predicted_start(const PathPoint& state, double target_volume) const;

  /// The pressure a volume step starts from: the start's own, or the least-squares estimate for its
  /// shape where it has none (the stress-free sheet).
  double start_pressure(const PathPoint& start) const;

  /// One volume step, from the predictor or from `resume` (the end of an unfinished attempt at the same
  /// volume, or a predictor already computed); updates `state` on success and `m_unfinished` on failure.
  /// `max_iterations` > 0 caps this attempt's Newton steps below the path's own limit.
  bool volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume = nullptr,
                   int max_iterations = 0);

  /// An attempt from `from` that ran out of iterations while still halving its residual (a slow creep, as
  /// when a local dimple pops through at a nearly constant pressure) is worth continuing where it ended:
  /// a smaller volume step would not help, since the pressure barely changes along such a path.
  ///
  /// Not a membrane's from the stress-free rest shape: with no out-of-plane stiffness to guide a far step,
  /// its creep there is not such a path, and a much shorter step converges in a fraction of the steps
  /// (inflate_to_volume cuts it to a quarter). The knot (200 mm, silicone x8): the step to 8 crept through
  /// four resumes (240 Newton steps), the halved ones to 4.5, 2.75 and 1.88 through 60-160 each, and the
  /// one to 1.44 converged in 13. The bent sheet keeps its resumes: the knot's bent step from rest to 8
  /// converged after two (132 steps) where its shorter steps crept.
  bool worth_resuming(const NewtonReport& report, const PathPoint& from) const;

  /// The path's first state when it starts from the rest shape itself (no initial guess): no pressure, no
  /// stress.
  bool stress_free(const PathPoint& state) const { return state.pressure == 0.0 && state.volume == m_rest_volume; }

  /// Cancelled or out of time: the run ends there (and m_stop says which).
  bool stopped(const NewtonReport& report);

  /// Volume control: volume steps from `state` to `target_volume` (mm^3), each doubled after an easy one
  /// and cut after a failed one; false, with why in `message`, when the path cannot go on.
  bool inflate_to_volume(PathPoint& state, double target_volume, std::string& message);

  /// One attempt at a volume step; one that fails creeping through wrinkles tries the sheet's bending once
  /// (try_bending_early). While that try is unused (a membrane under BendingUse::Auto), the attempt looks
  /// after CREEP_CHECK_STEPS already, so that bending is tried after 20 membrane steps rather than 60 (the
  /// 37k-vertex bunny with silicone to x8 crept 45 membrane steps of about 1 s each); unless that converged,
  /// the membrane attempt goes on from where it stood to its full step budget, as the one attempt it
  /// would have been.
  bool attempt_volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume);

  /// Under BendingUse::Auto, a volume step that failed as a pure membrane switches the sheet's bending
  /// stiffness on for the rest of the path (the hinges widen the solver's pattern). True if it did.
  bool switch_bending_on();

  /// The hinges widen (or narrow) the solver's pattern, and the inertia's factorization goes with it.
  void set_bending(bool on);

  /// A membrane under BendingUse::Auto that has not had its early bent try yet.
  bool early_bent_try_available() const;

  /// Once per path, the first volume step that creeps through wrinkles as a membrane is tried again with
  /// the sheet's bending on, from where the membrane attempt stood unless bending leaves that far from
  /// equilibrium (10 times the predictor's residual) or its walls have passed through each other there
  /// (else from the predictor). True if that converged (bending then stays on); else the sheet is a membrane
  /// again, with its unfinished attempt as before. `report` becomes the bent
  /// attempt's when that converged or was stopped (time limit, cancel), and stays the membrane's otherwise.
  /// A failed try that was still converging leaves its end in m_bent_try.unfinished, which the attempt
  /// right after bending goes on for good at this same step resumes instead of starting over. Without
  /// it the femur at ratio 2 crept through 4 membrane resumes (240 Newton steps) before bending went on;
  /// a bent attempt that fails costs the anchor and knot, whose membrane paths do reach an answer, one
  /// attempt.
  bool try_bending_early(PathPoint& state, double next_volume, NewtonReport& report);

  /// The early bent try was the step from `state` to `next_volume` and failed without being worth resuming
  /// (asked only while the sheet is still a membrane: a try that converged left bending on).
  bool bent_try_failed_for_good(const PathPoint& state, double next_volume) const;

  /// A path that struggles has often pushed its walls through each other (the knot's tube near x3.5):
  /// past that, this model (no contact) follows no physical balloon, and its Newton steps crept by the
  /// hundred there. So the equilibrium a hard step reached (more than CREEP_CHECK_STEPS Newton steps),
  /// and the one a failed attempt started from, are checked, once per state (one CGAL test, far cheaper
  /// than such a step), and the path ends there if it passes through itself. A path that never
  /// struggles is judged at its end only (inflate_simulated).
  bool stopped_passing_through_itself(const PathPoint& state, std::string& message);

  /// Pressure control: follow the volume path until the pressure reaches the target, then solve at
  /// that pressure. A target above the balloon's pressure maximum has no equilibrium and says so.
  bool inflate_to_pressure(PathPoint& state, double target_pressure, std::string& message);

  /// Notes the turn of the pressure at `previous`, the middle of three successive volume-path states
  /// (m_passed_extrema), where the pressure rose into it and falls after it, or the other way round.
  void note_pressure_turn(const PathPoint& before, const PathPoint& previous, const PathPoint& after);

  /// "the pressure fell after a maximum of P at volume ratio R", for messages about a passed `peak` (the
  /// path's highest state; where m_passed_extrema holds a maximum at least as high, that one's estimate).
  std::string fall_after(const PathPoint& peak) const;

  /// Pressure control asked for more than the path's highest pressure: the state goes back to that peak.
  bool above_maximum_pressure(PathPoint& state, const PathPoint& peak, double target_pressure, std::string& message);

  /// The equilibrium at `target_pressure` between two volume-path points whose pressures bracket it: a
  /// root of p(V) = target by regula falsi (Illinois, on log p against log (V - V_rest): PressureBracket)
  /// over volume-controlled solves, each started from the bracket's interpolation. A volume-controlled
  /// equilibrium whose multiplier is the target pressure is the pressure-controlled one, so the test is
  /// the pressure solve's own (|grad W - p grad V| within the tolerance). A Newton solve at fixed
  /// pressure from the interpolation crept instead where the bracket spans wrinkles (the knot: 128
  /// Newton steps, then the iteration limit).
  /// `state` becomes that equilibrium, or on failure the bracket's end closer to it.
  bool settle_at_pressure(PathPoint& state, PathPoint low, PathPoint high, double target_pressure, std::string& message);

  /// settle_at_pressure's last resort: Newton at the target pressure from the bracket's closer end.
  /// `failed` is why the bracket could not be closed, for the message when this fails too.
  bool settle_by_pressure_newton(PathPoint& state, const PathPoint& closer, double target_pressure,
                                 const NewtonReport& failed, std::string& message);

  /// Why a Hart-Smith path ends in non-finite numbers, in physical terms: its stiffening exp(k1 (I1 - 3)^2)
  /// outgrows double precision (hart-smith:G=0.1,k1=10,k2=1 ended "non-finite residual" past x10.5, at a
  /// pressure of 8e154 kPa). Empty unless the last equilibrium's pressure was above 1 GPa, which no rubber
  /// sheet bears (their tensile strengths are tens of MPa).
  std::string stiffening_overflow(const PathPoint& state) const;

  /// Why a volume path ends short of its target in physical terms when the last equilibrium it reached is
  /// unstable: empty when that one was stable. Such a path follows saddles (the knot with Mooney-Rivlin
  /// beyond x3: several bulges along the tube at the plateau pressure, 4-9 unstable modes), and near a fold
  /// of that branch every step fails while the stable states a real balloon would snap to lie out of reach.
  std::string unstable_path(const PathPoint& state) const;

  /// The result's shape, pressure, volumes, stretches, residual and counters at `state`.
  void fill(InflationResult& result, const PathPoint& state);

  const TriMesh& m_rest;
  const InflationOptions& m_options;
  fem::BalloonModel m_model;
  std::vector<bool> m_fixed;
  EquilibriumSolver m_solver;
  NewtonSettings m_settings;
  double m_start;
  int m_newton_iterations = 0;
  int m_load_steps = 0;
  int m_unstable_modes = 0;
  /// The early bent try (try_bending_early), once per path: its step, and where it ended when it failed
  /// while still converging (else empty).
  struct {
    double from_volume = -1.0, to_volume = -1.0;  ///< mm^3; negative until tried
    PathPoint unfinished;
  } m_bent_try;
  std::vector<PassedExtremum> m_passed_extrema;  ///< pressure control: since the last equilibrium asked for
  std::string m_final_message = "converged";  ///< the last equilibrium solve's (it may name a rounding floor)
  PathPoint m_unfinished;                   ///< where the last failed attempt ended
  double m_unfinished_start_residual = 0.0;  ///< N, the residual that attempt started from
  InflationStop m_stop = InflationStop::NoEquilibrium;
  PathPoint m_state;
  double m_rest_volume = 0.0;
  std::string m_problem;  ///< why the path cannot start; empty when it can
  std::unique_ptr<Inertia> m_inertia;  ///< made on first use
  bool m_path_predictor = false;  ///< see use_path_predictor()
  double m_self_checked_volume = 0.0;   ///< mm^3, the state stopped_passing_through_itself() last judged
  PathPoint m_previous;  ///< the equilibrium before the current state (path predictor)
  double m_last_newton_progress_s = m_start;  ///< steady-clock s of the last "newton" event (or the start)
};

}  // namespace balloon
