#include "solve/inflation_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh/mesh_geometry.hpp"
#include "mesh/self_intersection.hpp"
#include "solve/quantity_text.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon {
namespace {

/// Continuations of one volume step that is still converging slowly (see worth_resuming()).
constexpr int MAX_RESUMES = 4;
/// Newton steps of one attempt at a volume step.
constexpr int ATTEMPT_NEWTON_STEPS = 60;
/// Newton steps of an attempt after which, while the early bent try is still unused, a membrane that
/// creeps through wrinkles tries bending (see attempt_volume_step()).
constexpr int CREEP_CHECK_STEPS = 20;
/// The early bent try starts where the membrane attempt stood while the residual there, with bending on, is
/// below this multiple of the predictor's. Measured (bent residual there over the predictor's): 1.2-6.3
/// where that start saved 5-50 Newton steps (a double torus, a dumbbell, the retinal blob), 15-155 where
/// the hinges at the membrane's sharp folds made it fail (the knot and the dinosaur at 20 mm, ratio 2).
constexpr double BENT_START_RESIDUAL_FACTOR = 10.0;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Inertia::Inertia(const fem::BalloonModel& model, const std::vector<bool>& fixed)
    : m_assembly(model.faces(), model.vertex_count(), fixed, model.hinges()) {
  m_solver.set_pattern(m_assembly.free_count(), m_assembly.column_starts(), m_assembly.row_indices());
}

int Inertia::negative_eigenvalues(const fem::BalloonModel& model, const Eigen::VectorXd& x, double pressure_mpa) {
  model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  if (m_solver.factorize_ldlt(m_assembly.values()) != SparseSolver::Status::Ok) return -1;
  return m_solver.negative_pivots();
}

bool passes_through_itself(const TriMesh& rest, const Positions& deformed) {
  try {
    TriMesh inflated = rest;
    inflated.vertices = deformed;
    return mesh_self_intersects(inflated) && !mesh_self_intersects(rest);
  } catch (const std::invalid_argument&) {
    return false;
  }
}

InflationRun::InflationRun(const TriMesh& rest, const InflationOptions& options)
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

InflationResult InflationRun::run(const Positions* initial_guess) {
  start(initial_guess);
  return advance(m_options.control,
                 m_options.control == InflationControl::VolumeRatio ? m_options.volume_ratio : m_options.pressure_kpa);
}

std::string InflationRun::start(const Positions* initial_guess) {
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

InflationResult InflationRun::advance(InflationControl control, double target) {
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

int InflationRun::pressure_unstable_modes() {
  if (m_solver.factorize_at(m_state.x, m_state.pressure)) return 0;
  if (!m_inertia) m_inertia = std::make_unique<Inertia>(m_model, m_fixed);
  return m_inertia->negative_eigenvalues(m_model, m_state.x, m_state.pressure);
}

fem::BalloonModel InflationRun::make_model(const TriMesh& rest, const InflationOptions& options) {
  fem::BalloonModel model(rest, options.material, thicknesses(rest, options));
  model.set_tension_field(options.tension_field);
  model.set_bending(options.bending == BendingUse::On);
  return model;
}

std::vector<double> InflationRun::thicknesses(const TriMesh& rest, const InflationOptions& options) {
  if (!options.element_thickness_mm.empty()) return options.element_thickness_mm;
  return std::vector<double>(static_cast<size_t>(rest.face_count()), options.thickness_mm);
}

std::vector<bool> InflationRun::fixed_coordinates(const TriMesh& rest, const InflationOptions& options) {
  std::vector<bool> fixed(static_cast<size_t>(3 * rest.vertex_count()), false);
  if (options.fixed_vertices.empty()) {
    for (int c : rigid_support_coordinates(rest.vertices)) fixed[static_cast<size_t>(c)] = true;
  } else {
    for (int v : options.fixed_vertices)
      for (int a = 0; a < 3; ++a) fixed[static_cast<size_t>(3 * v + a)] = true;
  }
  return fixed;
}

double InflationRun::estimate_pressure(const Eigen::VectorXd& x) const {
  const auto& assembly = m_solver.assembly();
  const Eigen::VectorXd g = assembly.restrict(m_model.elastic_gradient(x));
  const Eigen::VectorXd v = assembly.restrict(m_model.volume_gradient(x));
  const double vv = v.squaredNorm();
  return vv > 0 ? g.dot(v) / vv : 0.0;
}

Eigen::VectorXd InflationRun::predict(const Eigen::VectorXd& x, double target_volume) const {
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

void InflationRun::add_shape_secant(const PathPoint& state, double target_volume, Eigen::VectorXd& x) const {
  if (has_user_fixed_vertices() || m_previous.x.size() != state.x.size()) return;
  if (!(m_previous.volume > 0.0) || !(state.volume > m_previous.volume * (1.0 + 1e-12))) return;
  const double theta = std::log(target_volume / state.volume) / std::log(state.volume / m_previous.volume);
  if (!(theta > 0.0) || theta > 4.0) return;
  const double s = std::cbrt(target_volume / state.volume);
  const Eigen::VectorXd deviation = state.x - predict(m_previous.x, state.volume);
  if (!deviation.allFinite()) return;
  x += theta * s * deviation;
}

void InflationRun::report_progress(const PathPoint& state, double residual, bool with_shape) {
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

void InflationRun::report_newton_progress(int iteration, double residual_norm, double pressure_mpa) {
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

PathPoint InflationRun::predicted_start(const PathPoint& state, double target_volume) const {
  PathPoint start{predict(state.x, target_volume), state.pressure, target_volume};
  if (m_path_predictor) {
    add_shape_secant(state, target_volume, start.x);
    start.pressure = estimate_pressure(start.x);
  }
  return start;
}

double InflationRun::start_pressure(const PathPoint& start) const {
  return start.pressure != 0.0 ? start.pressure : estimate_pressure(start.x);
}

bool InflationRun::volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume,
                               int max_iterations) {
  const PathPoint start = resume ? *resume : predicted_start(state, target_volume);
  Eigen::VectorXd x = start.x;
  double pressure = start_pressure(start);
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

bool InflationRun::worth_resuming(const NewtonReport& report, const PathPoint& from) const {
  if (stress_free(from) && !m_model.bending()) return false;
  return report.stop == NewtonStop::IterationLimit && std::isfinite(report.residual_norm) &&
         report.residual_norm < 0.5 * m_unfinished_start_residual;
}

bool InflationRun::stopped(const NewtonReport& report) {
  if (report.stop == NewtonStop::Cancelled) m_stop = InflationStop::Cancelled;
  if (report.stop == NewtonStop::TimeLimit) m_stop = InflationStop::TimeLimit;
  return report.stop == NewtonStop::Cancelled || report.stop == NewtonStop::TimeLimit;
}

bool InflationRun::inflate_to_volume(PathPoint& state, double target_volume, std::string& message) {
  m_passed_extrema.clear();  // volume control asks for every state it reports
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
      const double reached = state.volume / m_rest_volume, target = target_volume / m_rest_volume;
      message = report.message + " at volume ratio " + format_number_short_of(reached, target) + ", on the way to " +
                format_number(target);
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

bool InflationRun::attempt_volume_step(PathPoint& state, double target_volume, NewtonReport& report, const PathPoint* resume) {
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

bool InflationRun::switch_bending_on() {
  if (m_options.bending != BendingUse::Auto || m_model.bending()) return false;
  set_bending(true);
  return true;
}

void InflationRun::set_bending(bool on) {
  m_model.set_bending(on);
  m_solver.refresh_pattern();
  m_inertia.reset();
}

bool InflationRun::early_bent_try_available() const {
  return m_bent_try.to_volume < 0.0 && m_options.bending == BendingUse::Auto && !m_model.bending();
}

bool InflationRun::try_bending_early(PathPoint& state, double next_volume, NewtonReport& report) {
  if (!early_bent_try_available()) return false;
  m_bent_try.from_volume = state.volume;
  m_bent_try.to_volume = next_volume;
  set_bending(true);
  const PathPoint membrane_unfinished = m_unfinished;
  const double membrane_start_residual = m_unfinished_start_residual;
  NewtonReport bent;
  // From where the membrane attempt stood rather than from the predictor: that attempt has often done
  // most of the step (the fandisk with latex to x27: residual 55 -> 0.05 N in 20 membrane steps; the bent
  // try then took 15 Newton steps from the predictor, 5 from there). Not where its walls have passed
  // through each other (a bent equilibrium found from there keeps them so: femur x8, dino and anchor with
  // latex), nor where its sharp folds load the hinges far more than the predictor's residual (the dino at
  // 20 mm, latex x2: 235 N there, 1.6 N at the predictor).
  const PathPoint predicted = predicted_start(state, next_volume);
  auto bent_residual = [&](const PathPoint& point) { return m_solver.residual(point.x, start_pressure(point)).norm(); };
  const bool from_membrane_end = membrane_unfinished.volume == next_volume && membrane_unfinished.x.size() > 0 &&
                                 bent_residual(membrane_unfinished) <
                                     BENT_START_RESIDUAL_FACTOR * bent_residual(predicted) &&
                                 !passes_through_itself(m_rest, unflatten(membrane_unfinished.x));
  if (volume_step(state, next_volume, bent, from_membrane_end ? &membrane_unfinished : &predicted)) {
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

bool InflationRun::bent_try_failed_for_good(const PathPoint& state, double next_volume) const {
  return m_bent_try.unfinished.x.size() == 0 && m_bent_try.from_volume == state.volume &&
         m_bent_try.to_volume == next_volume;
}

bool InflationRun::stopped_passing_through_itself(const PathPoint& state, std::string& message) {
  if (!m_options.reject_self_intersection || state.volume == m_self_checked_volume) return false;
  m_self_checked_volume = state.volume;
  if (!passes_through_itself(m_rest, unflatten(state.x))) return false;
  m_stop = InflationStop::PassesThroughItself;
  message =
      "the equilibrium at volume ratio " + format_number(state.volume / m_rest_volume) + " passes through itself";
  return true;
}

std::string InflationRun::stiffening_overflow(const PathPoint& state) const {
  constexpr double NO_RUBBER_BEARS_MPA = 1e3;
  if (m_options.material.model != MaterialModel::HartSmith || !(state.pressure > NO_RUBBER_BEARS_MPA)) return "";
  return "; this rubber's Hart-Smith stiffening exp(k1 (I1 - 3)^2) (k1 = " + format_number(m_options.material.params[1]) +
         ") outgrows the numbers a computer holds: at the last equilibrium (volume ratio " +
         format_number(state.volume / m_rest_volume) + ", largest stretch " +
         format_number(m_model.max_stretch(state.x)) + ") the pressure was already " + format_kpa(state.pressure) +
         ", far beyond what any rubber bears before it bursts";
}

std::string InflationRun::unstable_path(const PathPoint& state) const {
  if (m_unstable_modes <= 0) return "";
  return "; the last equilibrium reached (volume ratio " + format_number(state.volume / m_rest_volume) + ", " +
         format_kpa(state.pressure) + ") is unstable, with " + std::to_string(m_unstable_modes) +
         (m_unstable_modes == 1 ? " direction" : " directions") +
         " along which the balloon would change shape at that volume by itself: the path had been following "
         "unstable equilibria, which a real balloon leaves, and no stable one was found";
}

void InflationRun::fill(InflationResult& result, const PathPoint& state) {
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
  result.passed_extrema = m_passed_extrema;
  result.newton_iterations = m_newton_iterations;
  result.factorizations = m_solver.factorizations();
  result.bending = m_model.bending();
  result.load_steps = m_load_steps;
  result.time_s = now_s() - m_start;
}

}  // namespace balloon
