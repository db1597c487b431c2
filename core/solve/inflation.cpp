#include "solve/inflation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fem/balloon_model.hpp"
#include "material/thin_sheet.hpp"
#include "mesh/cap_sliver_flips.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/self_intersection.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/pressure_bracket.hpp"
#include "solve/rigid_modes.hpp"
#include "solve/sparse_solver.hpp"

namespace balloon {
namespace {

constexpr double MPA_PER_KPA = 1e-3;
/// Continuations of one volume step that is still converging slowly (see worth_resuming()).
constexpr int MAX_RESUMES = 4;
/// Newton steps of one attempt at a volume step.
constexpr int ATTEMPT_NEWTON_STEPS = 60;
/// Pressure control past a pressure maximum below the target follows the volume path this far (V / V_rest,
/// issue 14's widest curve) for the pressure to climb back before it calls the target above the maximum.
constexpr double MAX_VOLUME_RATIO_PAST_A_PEAK = 250.0;
/// Volume-controlled solves that close the bracket around a target pressure at most (settle_at_pressure).
constexpr int MAX_BRACKET_STEPS = 40;
/// Newton steps of an attempt after which, while the early bent try is still unused, a membrane that
/// creeps through wrinkles tries bending (see attempt_volume_step()).
constexpr int CREEP_CHECK_STEPS = 20;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(3);
  out << value;
  return out.str();
}

/// A value short of `target`, with enough digits to show it (4.99996 short of 5 rather than "5").
std::string format_number_short_of(double value, double target) {
  for (int digits = 3; digits < 9; ++digits) {
    std::ostringstream out, goal;
    out.precision(digits);
    goal.precision(digits);
    out << value;
    goal << target;
    if (out.str() != goal.str()) return out.str();
  }
  return format_number(value);
}

std::string format_kpa(double mpa) {
  std::ostringstream out;
  out.precision(4);
  out << mpa / MPA_PER_KPA << " kPa";
  return out.str();
}

/// The deformed surface intersects itself while the rest surface does not (a rest mesh that already
/// does says nothing about the inflation). A mesh CGAL cannot take is not judged.
bool passes_through_itself(const TriMesh& rest, const Positions& deformed) {
  try {
    TriMesh inflated = rest;
    inflated.vertices = deformed;
    return mesh_self_intersects(inflated) && !mesh_self_intersects(rest);
  } catch (const std::invalid_argument&) {
    return false;
  }
}

/// The continuation state of an inflation: positions, pressure and the volume they satisfy.
struct PathPoint {
  Eigen::VectorXd x;
  double pressure = 0.0;
  double volume = 0.0;
};

/// The inertia of the exact stiffness, for states EquilibriumSolver's positive definite test rejects:
/// its own assembly and LDL^T, so the solver's factorization and state are left alone.
class Inertia {
 public:
  Inertia(const fem::BalloonModel& model, const std::vector<bool>& fixed)
      : m_assembly(model.faces(), model.vertex_count(), fixed, model.hinges()) {
    m_solver.set_pattern(m_assembly.free_count(), m_assembly.column_starts(), m_assembly.row_indices());
  }
  /// Negative eigenvalues of Hess(W - p V) at x; -1 when it is singular.
  int negative_eigenvalues(const fem::BalloonModel& model, const Eigen::VectorXd& x, double pressure_mpa) {
    model.assemble_hessian(x, pressure_mpa, m_assembly, false);
    if (m_solver.factorize_ldlt(m_assembly.values()) != SparseSolver::Status::Ok) return -1;
    return m_solver.negative_pivots();
  }

 private:
  fem::TriangleAssembly m_assembly;
  SparseSolver m_solver;
};

class InflationRun {
 public:
  InflationRun(const TriMesh& rest, const InflationOptions& options)
      : m_rest(rest),
        m_options(options),
        m_model(make_model(rest, options)),
        m_fixed(fixed_coordinates(rest, options)),
        m_solver(m_model, m_fixed),
        m_start(now_s()) {
    m_solver.set_support_is_rigid(!has_user_fixed_vertices());
    m_settings.relative_tolerance = options.residual_tolerance;
    m_settings.max_iterations = ATTEMPT_NEWTON_STEPS;
    m_settings.shift_restart = options.sqp_shift_restart;
    m_settings.shift_after_cut_short = options.sqp_shift_after_cut_short;
    m_settings.cancel = options.cancel;
    m_settings.deadline_s = options.max_time_s > 0 ? m_start + options.max_time_s : 0.0;
    if (options.progress)
      m_settings.on_iteration = [this](int iteration, double residual_norm, double pressure_mpa) {
        report_newton_progress(iteration, residual_norm, pressure_mpa);
      };
  }
  // m_settings.on_iteration holds `this`.
  InflationRun(const InflationRun&) = delete;
  InflationRun& operator=(const InflationRun&) = delete;

  InflationResult run(const Positions* initial_guess) {
    start(initial_guess);
    return advance(m_options.control,
                   m_options.control == InflationControl::VolumeRatio ? m_options.volume_ratio : m_options.pressure_kpa);
  }

  /// Sets the path's first state: the rest shape, or `initial_guess` (#V by 3, mm). Empty when usable,
  /// else why not (the rest mesh encloses no volume).
  std::string start(const Positions* initial_guess) {
    const Eigen::Map<const Eigen::VectorXd> rest_flat(m_rest.vertices.data(), m_rest.vertices.size());
    m_rest_volume = m_model.volume(rest_flat);
    m_state = PathPoint{rest_flat, 0.0, m_rest_volume};
    if (!(m_rest_volume > 0.0)) {
      m_problem = "the rest mesh encloses no positive volume (open, flat or oriented inwards)";
    } else if (initial_guess) {
      m_state.x = Eigen::Map<const Eigen::VectorXd>(initial_guess->data(), initial_guess->size());
      m_state.volume = m_model.volume(m_state.x);
      m_state.pressure = estimate_pressure(m_state.x);
    }
    return m_problem;
  }

  /// Continues the path from its current state to `target` (V / V_rest, or kPa under pressure control).
  /// A failed advance leaves the state at the last equilibrium the volume path reached.
  InflationResult advance(InflationControl control, double target) {
    InflationResult result;
    result.rest_volume_mm3 = m_rest_volume;
    m_stop = InflationStop::NoEquilibrium;
    bool ok = false;
    if (!m_problem.empty()) {
      m_stop = InflationStop::InvalidInput;
      result.message = m_problem;
    } else if (control == InflationControl::VolumeRatio) {
      ok = inflate_to_volume(m_state, target * m_rest_volume, result.message);
    } else {
      ok = inflate_to_pressure(m_state, target * MPA_PER_KPA, result.message);
    }
    result.converged = ok;
    result.stop = ok ? InflationStop::Converged : m_stop;
    if (ok) result.message = m_final_message;
    fill(result, m_state);
    return result;
  }

  /// Continuation predictor for a path of many targets (InflationPath): the shape secant below, and the
  /// least-squares pressure of the predicted shape rather than the last pressure. Together they save
  /// about one Newton step per curve point.
  void use_path_predictor() { m_path_predictor = true; }

  /// Unstable directions of the current state under pressure control: the negative eigenvalues of the
  /// stiffness K = Hess(W - p V) over the free coordinates (0 when K is positive definite). One
  /// supernodal LL^T; the LDL^T for the inertia only when that fails. -1 when K is singular.
  int pressure_unstable_modes() {
    if (m_solver.factorize_at(m_state.x, m_state.pressure)) return 0;
    if (!m_inertia) m_inertia = std::make_unique<Inertia>(m_model, m_fixed);
    return m_inertia->negative_eigenvalues(m_model, m_state.x, m_state.pressure);
  }

 private:
  static fem::BalloonModel make_model(const TriMesh& rest, const InflationOptions& options) {
    fem::BalloonModel model(rest, options.material, thicknesses(rest, options));
    model.set_tension_field(options.tension_field);
    model.set_bending(options.bending == BendingUse::On);
    return model;
  }

  static std::vector<double> thicknesses(const TriMesh& rest, const InflationOptions& options) {
    if (!options.element_thickness_mm.empty()) return options.element_thickness_mm;
    return std::vector<double>(static_cast<size_t>(rest.face_count()), options.thickness_mm);
  }

  static std::vector<bool> fixed_coordinates(const TriMesh& rest, const InflationOptions& options) {
    std::vector<bool> fixed(static_cast<size_t>(3 * rest.vertex_count()), false);
    if (options.fixed_vertices.empty()) {
      for (int c : rigid_support_coordinates(rest.vertices)) fixed[static_cast<size_t>(c)] = true;
    } else {
      for (int v : options.fixed_vertices)
        for (int a = 0; a < 3; ++a) fixed[static_cast<size_t>(3 * v + a)] = true;
    }
    return fixed;
  }

  bool has_user_fixed_vertices() const { return !m_options.fixed_vertices.empty(); }

  /// Least-squares pressure for a shape: the p minimising |grad W - p grad V|.
  double estimate_pressure(const Eigen::VectorXd& x) const {
    const auto& assembly = m_solver.assembly();
    const Eigen::VectorXd g = assembly.restrict(m_model.elastic_gradient(x));
    const Eigen::VectorXd v = assembly.restrict(m_model.volume_gradient(x));
    const double vv = v.squaredNorm();
    return vv > 0 ? g.dot(v) / vv : 0.0;
  }

  /// First guess at a new volume: scaled about the centroid for a free balloon (exact for a sphere),
  /// pushed along the vertex normals when vertices are held.
  Eigen::VectorXd predict(const Eigen::VectorXd& x, double target_volume) const {
    Eigen::VectorXd y = x;
    const double volume = m_model.volume(x);
    if (!has_user_fixed_vertices() && volume > 0) {
      const double s = std::cbrt(target_volume / volume);
      const Positions p = unflatten(x);
      const Eigen::RowVector3d center = p.colwise().mean();
      Positions scaled = (p.rowwise() - center) * s;
      scaled.rowwise() += center;
      return flat(scaled);
    }
    for (int pass = 0; pass < 3; ++pass) {
      Eigen::VectorXd v = m_model.volume_gradient(y);
      for (int c = 0; c < v.size(); ++c)
        if (m_fixed[static_cast<size_t>(c)]) v[c] = 0.0;
      const double vv = v.squaredNorm();
      if (!(vv > 0)) break;
      y += (target_volume - m_model.volume(y)) / vv * v;
    }
    return y;
  }

  /// Path predictor: the scaled guess plus the change of shape beyond scaling over the last step, carried
  /// on in proportion to log V (a secant on the deviation from a sphere's self-similar growth). On a
  /// discrete sphere it takes the Newton step that the uneven stretch of the polyhedron would cost.
  void add_shape_secant(const PathPoint& state, double target_volume, Eigen::VectorXd& x) const {
    if (has_user_fixed_vertices() || m_previous.x.size() != state.x.size()) return;
    if (!(m_previous.volume > 0.0) || !(state.volume > m_previous.volume * (1.0 + 1e-12))) return;
    const double theta = std::log(target_volume / state.volume) / std::log(state.volume / m_previous.volume);
    if (!(theta > 0.0) || theta > 4.0) return;
    const double s = std::cbrt(target_volume / state.volume);
    const Eigen::VectorXd deviation = state.x - predict(m_previous.x, state.volume);
    if (!deviation.allFinite()) return;
    x += theta * s * deviation;
  }

  void report_progress(const PathPoint& state, double residual, bool with_shape) {
    if (!m_options.progress) return;
    ProgressEvent event;
    event.phase = "inflate";
    event.iteration = m_load_steps;
    event.elapsed_s = now_s() - m_start;
    event.residual_norm = residual;
    event.pressure_kpa = state.pressure / MPA_PER_KPA;
    Positions shape;
    if (with_shape) {
      shape = unflatten(state.x);
      event.shape = &shape;
    }
    m_options.progress(event);
  }

  /// Phase "newton": the run's Newton iterations so far (the ones of this solve included), the current
  /// iterate's residual and pressure; at most one per InflationOptions::newton_progress_interval_s, no
  /// shape. (The first step of a 14k-vertex teddy with latex to x27 takes tens of seconds.)
  void report_newton_progress(int iteration, double residual_norm, double pressure_mpa) {
    const double now = now_s();
    if (now - m_last_newton_progress_s < m_options.newton_progress_interval_s) return;
    m_last_newton_progress_s = now;
    ProgressEvent event;
    event.phase = "newton";
    event.iteration = m_newton_iterations + iteration;
    event.elapsed_s = now - m_start;
    event.residual_norm = residual_norm;
    event.pressure_kpa = pressure_mpa / MPA_PER_KPA;
    m_options.progress(event);
  }

  /// One volume step, from the predictor or from `resume` (the end of an unfinished attempt at the same
  /// volume); updates `state` on success and `m_unfinished` on failure.
  /// `max_iterations` > 0 caps this attempt's Newton steps below the path's own limit.
  bool volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume = nullptr,
                   int max_iterations = 0) {
    Eigen::VectorXd x = resume ? resume->x : predict(state.x, target_volume);
    double pressure = resume ? resume->pressure : state.pressure;
    if (m_path_predictor && !resume) {
      add_shape_secant(state, target_volume, x);
      pressure = estimate_pressure(x);
    }
    if (pressure == 0.0) pressure = estimate_pressure(x);
    m_unfinished_start_residual = m_solver.residual(x, pressure).norm();
    NewtonSettings settings = m_settings;
    if (max_iterations > 0) settings.max_iterations = max_iterations;
    report = m_solver.solve_volume(x, pressure, target_volume, settings);
    m_newton_iterations += report.iterations;
    if (!report.converged) {
      m_unfinished = {x, pressure, target_volume};
      return false;
    }
    if (m_path_predictor) m_previous = state;
    state = {x, pressure, target_volume};
    m_unstable_modes = report.unstable_modes;
    m_final_message = report.message;
    ++m_load_steps;
    report_progress(state, report.residual_norm, true);
    return true;
  }

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
  bool worth_resuming(const NewtonReport& report, const PathPoint& from) const {
    if (stress_free(from) && !m_model.bending()) return false;
    return report.stop == NewtonStop::IterationLimit && std::isfinite(report.residual_norm) &&
           report.residual_norm < 0.5 * m_unfinished_start_residual;
  }

  /// The path's first state when it starts from the rest shape itself (no initial guess): no pressure, no
  /// stress.
  bool stress_free(const PathPoint& state) const { return state.pressure == 0.0 && state.volume == m_rest_volume; }

  /// Cancelled or out of time: the run ends there (and m_stop says which).
  bool stopped(const NewtonReport& report) {
    if (report.stop == NewtonStop::Cancelled) m_stop = InflationStop::Cancelled;
    if (report.stop == NewtonStop::TimeLimit) m_stop = InflationStop::TimeLimit;
    return report.stop == NewtonStop::Cancelled || report.stop == NewtonStop::TimeLimit;
  }

  bool inflate_to_volume(PathPoint& state, double target_volume, std::string& message) {
    double step = target_volume - state.volume;
    const double smallest = 1e-4 * std::abs(target_volume - state.volume) + 1e-12 * target_volume;
    NewtonReport report;
    if (std::abs(step) <= 1e-14 * target_volume) {
      // Already there in volume; still solve for equilibrium.
      if (volume_step(state, target_volume, report)) return true;
      message = "no equilibrium found: " + report.message;
      return false;
    }
    int resumes_left = MAX_RESUMES;
    bool from_bent_try = false;  // the next attempt continues the early bent try (see try_bending_early)
    bool hard_step = false;      // the last step took more than CREEP_CHECK_STEPS Newton steps
    while (std::abs(target_volume - state.volume) > 1e-14 * target_volume) {
      if (std::exchange(hard_step, false) && stopped_passing_through_itself(state, message)) return false;
      const double next = std::abs(step) >= std::abs(target_volume - state.volume) ? target_volume : state.volume + step;
      const PathPoint* resume = std::exchange(from_bent_try, false) ? &m_bent_try.unfinished : nullptr;
      const int newton_before = m_newton_iterations;
      if (attempt_volume_step(state, next, report, resume)) {
        if (report.iterations <= 6) step *= 2.0;
        resumes_left = MAX_RESUMES;
        hard_step = m_newton_iterations - newton_before > CREEP_CHECK_STEPS;
        continue;
      }
      if (report.stop != NewtonStop::Cancelled && stopped_passing_through_itself(state, message)) return false;
      while (!stopped(report) && worth_resuming(report, state) && resumes_left > 0) {
        --resumes_left;
        const PathPoint unfinished = m_unfinished;
        if (volume_step(state, next, report, &unfinished)) break;
      }
      hard_step = report.converged;
      if (report.converged) continue;
      if (stopped(report)) {
        // Where it got to: the last equilibrium, which the result holds.
        message = report.message + " at volume ratio " + format_number_short_of(state.volume / m_rest_volume, target_volume / m_rest_volume) +
                  ", on the way to " + format_number(target_volume / m_rest_volume);
        return false;
      }
      if (creeping_through_wrinkles(report) && switch_bending_on()) {
        // The same step, now with a stable state: from where the early bent try of this very step ended,
        // rather than repeating it from the predictor. Where that try failed for good, the same attempt
        // would fail the same way (it is deterministic), so the step is cut at once.
        from_bent_try = m_bent_try.unfinished.x.size() > 0 && m_bent_try.unfinished.volume == next;
        if (from_bent_try || !bent_try_failed_for_good(state, next)) continue;
      }
      step *= stress_free(state) ? 0.25 : 0.5;  // from rest, membrane or bent: see worth_resuming()
      if (std::abs(step) < smallest) {
        message = "no equilibrium found at volume ratio " + format_number(next / m_rest_volume) +
                  " (" + report.message + ", residual " + format_number(report.residual_norm) + " N against a tolerance of " +
                  format_number(m_settings.relative_tolerance * m_solver.force_scale(state.x, state.pressure)) + " N)";
        if (report.stop == NewtonStop::NonFinite) message += stiffening_overflow(state);
        message += unstable_path(state);
        return false;
      }
    }
    return true;
  }

  /// One attempt at a volume step; one that fails creeping through wrinkles tries the sheet's bending once
  /// (try_bending_early). While that try is unused (a membrane under BendingUse::Auto), the attempt looks
  /// after CREEP_CHECK_STEPS already, so that bending is tried after 20 membrane steps rather than 60 (the
  /// 37k-vertex bunny with silicone to x8 crept 45 membrane steps of about 1 s each); unless that converged,
  /// the membrane attempt goes on from where it stood to its full step budget, as the one attempt it
  /// would have been.
  bool attempt_volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume) {
    if (!early_bent_try_available()) {
      if (volume_step(state, target_volume, report, resume)) return true;
    } else if (volume_step(state, target_volume, report, resume, CREEP_CHECK_STEPS)) {
      return true;
    } else if (report.stop == NewtonStop::IterationLimit && std::isfinite(report.residual_norm)) {
      if (creeping_through_wrinkles(report)) {
        if (try_bending_early(state, target_volume, report)) return true;
        if (stopped(report)) return false;
      }
      const PathPoint unfinished = m_unfinished;
      const double start_residual = m_unfinished_start_residual;
      if (volume_step(state, target_volume, report, &unfinished, m_settings.max_iterations - CREEP_CHECK_STEPS))
        return true;
      m_unfinished_start_residual = start_residual;  // worth_resuming() judges the attempt as a whole
    }
    return !stopped(report) && creeping_through_wrinkles(report) && try_bending_early(state, target_volume, report);
  }

  /// Under BendingUse::Auto, a volume step that failed as a pure membrane switches the sheet's bending
  /// stiffness on for the rest of the path (the hinges widen the solver's pattern). True if it did.
  bool switch_bending_on() {
    if (m_options.bending != BendingUse::Auto || m_model.bending()) return false;
    set_bending(true);
    return true;
  }

  /// The hinges widen (or narrow) the solver's pattern, and the inertia's factorization goes with it.
  void set_bending(bool on) {
    m_model.set_bending(on);
    m_solver.refresh_pattern();
    m_inertia.reset();
  }

  /// A membrane under BendingUse::Auto that has not had its early bent try yet.
  bool early_bent_try_available() const {
    return m_bent_try.to_volume < 0.0 && m_options.bending == BendingUse::Auto && !m_model.bending();
  }

  /// Once per path, the first volume step that creeps through wrinkles as a membrane is tried again with
  /// the sheet's bending on, from where it started. True if that converged (bending then stays on); else
  /// the sheet is a membrane again, with its unfinished attempt as before. `report` becomes the bent
  /// attempt's when that converged or was stopped (time limit, cancel), and stays the membrane's otherwise.
  /// A failed try that was still converging leaves its end in m_bent_try.unfinished, which the attempt
  /// right after bending goes on for good at this same step resumes instead of starting over. Without
  /// it the femur at ratio 2 crept through 4 membrane resumes (240 Newton steps) before bending went on;
  /// a bent attempt that fails costs the anchor and knot, whose membrane paths do reach an answer, one
  /// attempt.
  bool try_bending_early(PathPoint& state, double next_volume, NewtonReport& report) {
    if (!early_bent_try_available()) return false;
    m_bent_try.from_volume = state.volume;
    m_bent_try.to_volume = next_volume;
    set_bending(true);
    const PathPoint membrane_unfinished = m_unfinished;
    const double membrane_start_residual = m_unfinished_start_residual;
    NewtonReport bent;
    if (volume_step(state, next_volume, bent)) {
      report = bent;
      return true;
    }
    if (stopped(bent)) {
      report = bent;
      return false;
    }
    if (worth_resuming(bent, state)) m_bent_try.unfinished = m_unfinished;
    set_bending(false);
    m_unfinished = membrane_unfinished;
    m_unfinished_start_residual = membrane_start_residual;
    return false;
  }

  /// The early bent try was the step from `state` to `next_volume` and failed without being worth resuming
  /// (asked only while the sheet is still a membrane: a try that converged left bending on).
  bool bent_try_failed_for_good(const PathPoint& state, double next_volume) const {
    return m_bent_try.unfinished.x.size() == 0 && m_bent_try.from_volume == state.volume &&
           m_bent_try.to_volume == next_volume;
  }

  /// A path that struggles has often pushed its walls through each other (the knot's tube near x3.5):
  /// past that, this model (no contact) follows no physical balloon, and its Newton steps crept by the
  /// hundred there. So the equilibrium a hard step reached (more than CREEP_CHECK_STEPS Newton steps),
  /// and the one a failed attempt started from, are checked, once per state (one CGAL test, far cheaper
  /// than such a step), and the path ends there if it passes through itself. A path that never
  /// struggles is judged at its end only (inflate_simulated).
  bool stopped_passing_through_itself(const PathPoint& state, std::string& message) {
    if (!m_options.reject_self_intersection || state.volume == m_self_checked_volume) return false;
    m_self_checked_volume = state.volume;
    if (!passes_through_itself(m_rest, unflatten(state.x))) return false;
    m_stop = InflationStop::PassesThroughItself;
    message =
        "the equilibrium at volume ratio " + format_number(state.volume / m_rest_volume) + " passes through itself";
    return true;
  }

  /// Pressure control: follow the volume path until the pressure reaches the target, then solve at
  /// that pressure. A target above the balloon's pressure maximum has no equilibrium and says so.
  bool inflate_to_pressure(PathPoint& state, double target_pressure, std::string& message) {
    if (target_pressure <= 0.0) {
      message = "pressure must be positive";
      return false;
    }
    const double rest_volume = m_rest_volume;
    double step = 0.5 * rest_volume;
    // The highest pressure on the path so far, and where; past a maximum below the target the path goes
    // on, for the pressure may climb again (a lobe that popped, a stiffening rubber's third branch).
    // `snapped_from`: once the pressure fell, the highest pressure before the latest fall, where a balloon
    // held at the target pressure snaps (the path's last step, past the target, is no maximum it passed).
    PathPoint peak = state;
    std::optional<PathPoint> snapped_from;
    NewtonReport report;
    while (state.pressure < target_pressure) {
      PathPoint previous = state;
      if (!volume_step(state, state.volume + step, report)) {
        if (report.stop != NewtonStop::Cancelled && stopped_passing_through_itself(state, message)) {
          if (snapped_from)
            message += "; before that " + fall_after(*snapped_from) + ", below the " + format_kpa(target_pressure) + " asked for";
          return false;
        }
        if (stopped(report)) {
          message = report.message;
          return false;
        }
        if (creeping_through_wrinkles(report) && switch_bending_on()) continue;
        step *= 0.5;
        if (step < 1e-5 * rest_volume) {
          // Past a peak, a path that ends leaves the peak the highest pressure this balloon holds.
          if (snapped_from) return above_maximum_pressure(state, peak, target_pressure, message);
          message = "no equilibrium found on the way to " + format_kpa(target_pressure) + " (" + report.message + ")";
          return false;
        }
        continue;
      }
      if (state.pressure > peak.pressure) peak = state;
      if (state.pressure < previous.pressure) snapped_from = peak;
      if (state.pressure < target_pressure && snapped_from && state.volume > MAX_VOLUME_RATIO_PAST_A_PEAK * rest_volume)
        return above_maximum_pressure(state, peak, target_pressure, message);
      if (state.pressure < target_pressure && state.volume > 1e6 * rest_volume) {
        message = "no equilibrium below volume ratio 1e6 for " + format_kpa(target_pressure);
        return false;
      }
      if (state.pressure >= target_pressure) {
        if (!settle_at_pressure(state, previous, state, target_pressure, message)) return false;
        if (snapped_from)
          m_final_message += "; on the way " + fall_after(*snapped_from) +
                             ": at that pressure the balloon snaps to a larger shape, and this is the one it reaches";
        return true;
      }
      if (report.iterations <= 6) step *= 2.0;
    }
    return true;
  }

  /// "the pressure fell after a maximum of P at volume ratio R", for messages about a passed `peak`.
  std::string fall_after(const PathPoint& peak) const {
    return "the pressure fell after a maximum of " + format_kpa(peak.pressure) + " at volume ratio " +
           format_number(peak.volume / m_rest_volume);
  }

  /// Pressure control asked for more than the path's highest pressure: the state goes back to that peak.
  bool above_maximum_pressure(PathPoint& state, const PathPoint& peak, double target_pressure, std::string& message) {
    m_stop = InflationStop::AboveMaximumPressure;
    message = "no equilibrium: " + format_kpa(target_pressure) + " exceeds the balloon's maximum pressure of about " +
              format_kpa(peak.pressure) + " (the highest on its volume path up to volume ratio " +
              format_number(state.volume / m_rest_volume) + "; use volume control to pass it)";
    state = peak;
    return false;
  }

  /// The equilibrium at `target_pressure` between two volume-path points whose pressures bracket it: a
  /// root of p(V) = target by regula falsi (Illinois, on log p against log (V - V_rest): PressureBracket)
  /// over volume-controlled solves, each started from the bracket's interpolation. A volume-controlled
  /// equilibrium whose multiplier is the target pressure is the pressure-controlled one, so the test is
  /// the pressure solve's own (|grad W - p grad V| within the tolerance). A Newton solve at fixed
  /// pressure from the interpolation crept instead where the bracket spans wrinkles (the knot: 128
  /// Newton steps, then the iteration limit).
  /// `state` becomes that equilibrium, or on failure the bracket's end closer to it.
  bool settle_at_pressure(PathPoint& state, PathPoint low, PathPoint high, double target_pressure, std::string& message) {
    PressureBracket bracket(m_rest_volume, target_pressure, {low.volume, low.pressure}, {high.volume, high.pressure});
    NewtonReport report;
    auto closer_end = [&]() -> PathPoint& {
      return target_pressure - low.pressure < high.pressure - target_pressure ? low : high;
    };
    for (int bracket_step = 0; bracket_step < MAX_BRACKET_STEPS; ++bracket_step) {
      PathPoint& closer = closer_end();
      if (m_solver.residual(closer.x, target_pressure).norm() <=
          m_settings.relative_tolerance * m_solver.force_scale(closer.x, target_pressure)) {
        state = {closer.x, target_pressure, closer.volume};
        m_final_message = "converged";
        return true;
      }
      const double volume = bracket.next_volume();
      const double theta = (volume - low.volume) / (high.volume - low.volume);
      PathPoint guess{low.x + theta * (high.x - low.x), target_pressure, volume};
      // From the interpolation, else as the path steps: from the lower end's equilibrium, scaled.
      PathPoint reached = low;
      bool solved = volume_step(reached, guess.volume, report, &guess);
      // A membrane that fails here tries again with the sheet's bending. A target far below the path's
      // first pressure lies near the rest volume, where a membrane is nearly slack: a rounded box's faces
      // wrinkled (Mooney-Rivlin, 0.01 kPa), and the dinosaur (latex, 0.05 kPa, x1.008) pillowed at almost
      // no pressure, its solve creeping to the iteration limit with K positive definite. Its bending
      // stiffness, which the real sheet has, makes both converge.
      if (!solved && !stopped(report) && switch_bending_on())
        solved = volume_step(reached, guess.volume, report, &guess);
      if (!solved && !stopped(report) && !volume_step(reached, guess.volume, report)) {
        if (stopped(report)) {
          message = report.message;
          state = closer;
          return false;
        }
        // The spool with latex, whose pressure triples between two path points, failed its volume solves
        // in between.
        return settle_by_pressure_newton(state, closer, target_pressure, report, message);
      }
      (bracket.narrow({reached.volume, reached.pressure}) ? low : high) = reached;
    }
    // The volume solves in between landed on other branches (the rotor at half size with latex: p(V) jumps).
    report.message = "the bracket did not close in " + std::to_string(MAX_BRACKET_STEPS) + " volume steps";
    report.residual_norm = 0.0;  // each of those converged
    return settle_by_pressure_newton(state, closer_end(), target_pressure, report, message);
  }

  /// settle_at_pressure's last resort: Newton at the target pressure from the bracket's closer end.
  /// `failed` is why the bracket could not be closed, for the message when this fails too.
  bool settle_by_pressure_newton(PathPoint& state, const PathPoint& closer, double target_pressure,
                                 const NewtonReport& failed, std::string& message) {
    Eigen::VectorXd x = closer.x;
    const NewtonReport at_pressure = m_solver.solve_pressure(x, target_pressure, m_settings);
    m_newton_iterations += at_pressure.iterations;
    if (at_pressure.converged) {
      state = {x, target_pressure, m_model.volume(x)};
      m_final_message = at_pressure.message;
      return true;
    }
    if (stopped(at_pressure)) {
      message = at_pressure.message;
    } else {
      message = "no equilibrium found at " + format_kpa(target_pressure) + " (" + failed.message +
                (failed.residual_norm > 0.0 ? ", residual " + format_number(failed.residual_norm) + " N" : "") +
                "; then at that pressure: " + at_pressure.message + ")";
    }
    state = closer;
    return false;
  }

  /// Why a Hart-Smith path ends in non-finite numbers, in physical terms: its stiffening exp(k1 (I1 - 3)^2)
  /// outgrows double precision (hart-smith:G=0.1,k1=10,k2=1 ended "non-finite residual" past x10.5, at a
  /// pressure of 8e154 kPa). Empty unless the last equilibrium's pressure was above 1 GPa, which no rubber
  /// sheet bears (their tensile strengths are tens of MPa).
  std::string stiffening_overflow(const PathPoint& state) const {
    constexpr double NO_RUBBER_BEARS_MPA = 1e3;
    if (m_options.material.model != MaterialModel::HartSmith || !(state.pressure > NO_RUBBER_BEARS_MPA)) return "";
    return "; this rubber's Hart-Smith stiffening exp(k1 (I1 - 3)^2) (k1 = " + format_number(m_options.material.params[1]) +
           ") outgrows the numbers a computer holds: at the last equilibrium (volume ratio " +
           format_number(state.volume / m_rest_volume) + ", largest stretch " +
           format_number(m_model.max_stretch(state.x)) + ") the pressure was already " + format_kpa(state.pressure) +
           ", far beyond what any rubber bears before it bursts";
  }

  /// Why a volume path ends short of its target in physical terms when the last equilibrium it reached is
  /// unstable: empty when that one was stable. Such a path follows saddles (the knot with Mooney-Rivlin
  /// beyond x3: several bulges along the tube at the plateau pressure, 4-9 unstable modes), and near a fold
  /// of that branch every step fails while the stable states a real balloon would snap to lie out of reach.
  std::string unstable_path(const PathPoint& state) const {
    if (m_unstable_modes <= 0) return "";
    return "; the last equilibrium reached (volume ratio " + format_number(state.volume / m_rest_volume) + ", " +
           format_kpa(state.pressure) + ") is unstable, with " + std::to_string(m_unstable_modes) +
           (m_unstable_modes == 1 ? " direction" : " directions") +
           " along which the balloon would change shape at that volume by itself: the path had been following "
           "unstable equilibria, which a real balloon leaves, and no stable one was found";
  }

  void fill(InflationResult& result, const PathPoint& state) {
    result.deformed = unflatten(state.x);
    result.pressure_kpa = state.pressure / MPA_PER_KPA;
    result.volume_mm3 = m_model.volume(state.x);
    result.volume_ratio = result.volume_mm3 / result.rest_volume_mm3;
    result.mean_stretch = std::sqrt(m_model.area(state.x) / m_model.rest_area());
    result.max_stretch = m_model.max_stretch(state.x);
    // Residual over every coordinate except user-held ones: the rigid support must carry no load.
    Eigen::VectorXd r = m_model.elastic_gradient(state.x) - state.pressure * m_model.volume_gradient(state.x);
    for (int v : m_options.fixed_vertices) r.segment<3>(3 * v).setZero();
    result.residual_norm = r.norm();
    result.unstable_modes = m_unstable_modes;
    result.wrinkled_elements = m_model.tension_field() ? m_model.relaxed_triangle_count(state.x) : 0;
    result.newton_iterations = m_newton_iterations;
    result.factorizations = m_solver.factorizations();
    result.bending = m_model.bending();
    result.load_steps = m_load_steps;
    result.time_s = now_s() - m_start;
  }

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

/// The mesh and options a run simulates: the rest mesh with its cap slivers flipped away (same vertices,
/// so its deformed positions are the caller's), a flipped pair taking the mean of its two thicknesses.
struct SimulationMesh {
  TriMesh rest;
  InflationOptions options;
  int flipped_cap_slivers = 0;
};

SimulationMesh simulation_mesh(const TriMesh& rest, const InflationOptions& options) {
  CapSliverFlips flips = flip_cap_slivers(rest);
  SimulationMesh simulated{TriMesh{rest.vertices, std::move(flips.faces)}, options,
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
      : problem(options_problem(rest_mesh, path_options)) {
    if (problem.empty()) {
      simulated = simulation_mesh(rest_mesh, path_options);
      run = std::make_unique<InflationRun>(simulated.rest, simulated.options);
      run->use_path_predictor();
    } else {
      simulated.rest = rest_mesh;
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
  if (m->run) m->problem = m->run->start(initial_guess);
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
    result.deformed = m->simulated.rest.vertices;
    return result;
  }
  InflationResult result = m->run->advance(control, target);
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
  InflationResult result = inflate_simulated(simulated, initial_guess);
  result.flipped_cap_slivers = simulated.flipped_cap_slivers;
  return result;
}

}  // namespace balloon
