#include "solve/equilibrium_solver.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "solve/rigid_modes.hpp"

namespace balloon {

namespace {
/// An SQP step along a direction softer than its model is tried at up to 2^MAX_STEP_DOUBLINGS times its
/// length (constrained_descent).
constexpr int MAX_STEP_DOUBLINGS = 5;
/// A residual up to this multiple of its measured rounding level is rounding (the measure is the
/// difference of two evaluations' errors, so it scatters about them by a factor of about 2).
constexpr double ROUNDING_MARGIN = 3.0;
/// Never accept a floor above this fraction of the force scale: an equilibrium so blurred is not one.
constexpr double MAX_ROUNDING_FLOOR = 1e-5;
/// With the residual at its floor, the volume counts as met within this fraction of the target (a sum of
/// #F terms, so about a thousand roundings of it), should the tolerance ask for more.
constexpr double VOLUME_ROUNDING = 1e-12;
/// Close to a solution (residual below NEAR_SADDLE_RESIDUAL of the force scale) whose exact stiffness
/// has unstable modes, SQP steps whose residual has not halved in SADDLE_CREEP_STEPS steps are creeping,
/// and the next ones use the exact Hessian, shifted (sqp_step).
constexpr double NEAR_SADDLE_RESIDUAL = 1e-2;
constexpr size_t SADDLE_CREEP_STEPS = 4;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool should_stop(const NewtonSettings& settings, NewtonReport& report) {
  if (settings.cancel && settings.cancel->cancelled()) {
    report.stop = NewtonStop::Cancelled;
    report.message = "cancelled";
    return true;
  }
  if (settings.deadline_s > 0.0 && now_s() > settings.deadline_s) {
    report.stop = NewtonStop::TimeLimit;
    report.message = "time limit reached";
    return true;
  }
  return false;
}

std::string converged_message(const NewtonReport& report) {
  char text[160];
  if (report.stagnated_at > 0.0) {
    std::snprintf(text, sizeof(text), "converged to %.3g N, %.2gx the force tolerance, where Newton stagnated",
                  report.residual_norm, report.stagnated_at);
    return text;
  }
  if (report.rounding_floor <= 0.0) return "converged";
  std::snprintf(text, sizeof(text), "converged at the residual's rounding floor (%.3g N, at most %.3g N)",
                report.residual_norm, report.rounding_floor);
  return text;
}

}  // namespace

const char* newton_stop_word(NewtonStop stop) {
  switch (stop) {
    case NewtonStop::Converged: return "converged";
    case NewtonStop::IterationLimit: return "iteration_limit";
    case NewtonStop::LineSearchFailed: return "line_search_failed";
    case NewtonStop::NotFactorizable: return "not_factorizable";
    case NewtonStop::NonFinite: return "non_finite";
    case NewtonStop::Cancelled: return "cancelled";
    case NewtonStop::TimeLimit: return "time_limit";
    case NewtonStop::Slow: return "slow";
  }
  return "unknown";
}

EquilibriumSolver::EquilibriumSolver(fem::BalloonModel& model, const std::vector<bool>& fixed_coordinate)
    : m_model(model), m_assembly(model.faces(), model.vertex_count(), fixed_coordinate, model.hinges()) {
  m_solver.set_pattern(m_assembly.free_count(), m_assembly.column_starts(), m_assembly.row_indices());
  double mean_thickness = 0.0;
  for (int f = 0; f < m_model.faces().rows(); ++f) mean_thickness += m_model.thickness(f);
  mean_thickness /= static_cast<double>(std::max<Eigen::Index>(1, m_model.faces().rows()));
  // A thousandth of the membrane force a unit strain would cause over the surface.
  m_force_floor = 1e-3 * m_model.material().shear_modulus() * mean_thickness * std::sqrt(m_model.rest_area());
}

void EquilibriumSolver::refresh_pattern() {
  std::vector<bool> fixed(static_cast<size_t>(3 * m_model.vertex_count()));
  for (int c = 0; c < 3 * m_model.vertex_count(); ++c) fixed[static_cast<size_t>(c)] = m_assembly.free_index(c) < 0;
  m_assembly = fem::TriangleAssembly(m_model.faces(), m_model.vertex_count(), fixed, m_model.hinges());
  m_solver.set_pattern(m_assembly.free_count(), m_assembly.column_starts(), m_assembly.row_indices());
  m_skip_ldlt = 0;
  m_exact_fails_left = 0;
  m_last_unstable_modes = 0;
  m_sqp_shift = 0.0;
  m_sqp_cut_short = false;
  m_sqp_unshifted_steps = 0;
  m_last_step_exact = false;
  m_exact_indefinite = false;
  m_sqp_indefinite = false;
}

Eigen::VectorXd EquilibriumSolver::residual(const Eigen::VectorXd& x, double pressure_mpa) const {
  Eigen::VectorXd r = m_model.elastic_gradient(x) - pressure_mpa * m_model.volume_gradient(x);
  for (int c = 0; c < r.size(); ++c)
    if (m_assembly.free_index(c) < 0) r[c] = 0.0;
  return r;
}

double EquilibriumSolver::force_scale(const Eigen::VectorXd& x, double pressure_mpa) const {
  Eigen::VectorXd v = m_model.volume_gradient(x);
  for (int c = 0; c < v.size(); ++c)
    if (m_assembly.free_index(c) < 0) v[c] = 0.0;
  return std::abs(pressure_mpa) * v.norm() + m_force_floor;
}

double EquilibriumSolver::residual_rounding(const Eigen::VectorXd& x, double pressure_mpa,
                                            const Eigen::VectorXd& r) const {
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> points(x.data(), x.size() / 3, 3);
  const double size = (points.colwise().maxCoeff() - points.colwise().minCoeff()).maxCoeff();
  // Not along an axis, and of the shape's size: every coordinate's low bits change, none grows much.
  const Eigen::RowVector3d shift = size * Eigen::RowVector3d(0.31, 0.43, 0.57);
  Eigen::VectorXd moved = x;
  for (Eigen::Index v = 0; v < points.rows(); ++v) moved.segment<3>(3 * v) += shift.transpose();
  return (m_assembly.restrict(residual(moved, pressure_mpa)) - r).norm();
}

bool EquilibriumSolver::at_rounding_floor(const Eigen::VectorXd& x, double pressure_mpa, const Eigen::VectorXd& r,
                                          double previous_residual, double force_scale_n, NewtonReport& report) const {
  const double residual_norm = report.residual_norm;
  if (report.iterations == 0 || residual_norm <= 0.5 * previous_residual) return false;  // still converging
  const double floor = ROUNDING_MARGIN * residual_rounding(x, pressure_mpa, r);
  if (!(residual_norm <= floor && floor <= MAX_ROUNDING_FLOOR * force_scale_n)) return false;
  report.rounding_floor = floor;
  return true;
}

bool EquilibriumSolver::factorize_stiffness(const Eigen::VectorXd& x, double pressure_mpa) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  if (m_solver.factorize_llt(m_assembly.values()) == SparseSolver::Status::Ok) return true;
  // Not a stable configuration: shift until positive definite (a damped, inexact Newton step).
  const double base = std::max(1e-30, m_assembly.mean_abs_diagonal());
  for (double shift = 1e-6 * base; shift < 1e6 * base; shift *= 10.0) {
    if (m_solver.factorize_llt(m_assembly.values(), shift) == SparseSolver::Status::Ok) return true;
  }
  return false;
}

bool EquilibriumSolver::factorize_at(const Eigen::VectorXd& x, double pressure_mpa) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  return m_solver.factorize_llt(m_assembly.values()) == SparseSolver::Status::Ok;
}

bool EquilibriumSolver::factorize_exact(const Eigen::VectorXd& x, double pressure_mpa) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  if (!m_exact_indefinite && m_solver.factorize_llt(m_assembly.values()) == SparseSolver::Status::Ok) return true;
  return factorize_exact_ldlt();
}

bool EquilibriumSolver::factorize_exact_ldlt() {
  const bool ok = m_solver.factorize_ldlt(m_assembly.values()) == SparseSolver::Status::Ok;
  m_exact_indefinite = ok && m_solver.negative_pivots() > 0;
  return ok;
}

Eigen::VectorXd EquilibriumSolver::stiffness_times(const Eigen::VectorXd& x, double pressure_mpa,
                                                   const Eigen::VectorXd& w) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  return m_assembly.extend(m_assembly.multiply(m_assembly.restrict(w)));
}

Eigen::VectorXd EquilibriumSolver::solve_with_factorization(const Eigen::VectorXd& b) const {
  return m_assembly.extend(m_solver.solve(m_assembly.restrict(b)));
}

void EquilibriumSolver::set_support_is_rigid(bool rigid) {
  m_support.clear();
  if (!rigid) return;
  for (int c = 0; c < 3 * m_model.vertex_count(); ++c)
    if (m_assembly.free_index(c) < 0) m_support.push_back(c);
}

void EquilibriumSolver::return_to_support(Eigen::VectorXd& x, const Eigen::VectorXd& held, double pressure_mpa,
                                          NewtonReport& report) const {
  if (m_support.empty() || !restore_rigid_support(x, held, m_support)) return;
  // The rigid motion leaves |r| unchanged up to the support's reactions, which vanish at equilibrium.
  if (std::isfinite(report.residual_norm)) report.residual_norm = m_assembly.restrict(residual(x, pressure_mpa)).norm();
}

NewtonReport EquilibriumSolver::solve_volume(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                                             const NewtonSettings& settings) {
  const Eigen::VectorXd held = m_support.empty() ? Eigen::VectorXd() : x;  // only a rigid support returns
  NewtonReport report = newton_volume(x, pressure_mpa, target_volume, settings);
  return_to_support(x, held, pressure_mpa, report);
  return report;
}

NewtonReport EquilibriumSolver::solve_pressure(Eigen::VectorXd& x, double pressure_mpa, const NewtonSettings& settings) {
  NewtonReport report;
  auto total_energy = [&](const Eigen::VectorXd& y) { return m_model.elastic_energy(y) - pressure_mpa * m_model.volume(y); };
  double previous_residual = std::numeric_limits<double>::infinity();
  for (report.iterations = 0;; ++report.iterations) {
    const Eigen::VectorXd r = m_assembly.restrict(residual(x, pressure_mpa));
    report.residual_norm = r.norm();
    const double scale = force_scale(x, pressure_mpa);
    const double tolerance = settings.relative_tolerance * scale;
    if (!std::isfinite(report.residual_norm)) {
      report.stop = NewtonStop::NonFinite;
      report.message = "non-finite residual";
      return report;
    }
    const double previous = std::exchange(previous_residual, report.residual_norm);
    if (report.residual_norm <= tolerance || at_rounding_floor(x, pressure_mpa, r, previous, scale, report)) {
      report.converged = true;
      report.stop = NewtonStop::Converged;
      report.message = converged_message(report);
      return report;
    }
    if (report.iterations >= settings.max_iterations) {
      report.stop = NewtonStop::IterationLimit;
      report.message = "Newton iteration limit reached";
      return report;
    }
    if (settings.on_iteration) settings.on_iteration(report.iterations, report.residual_norm, pressure_mpa);
    if (should_stop(settings, report)) return report;
    if (!factorize_stiffness(x, pressure_mpa)) {
      report.stop = NewtonStop::NotFactorizable;
      report.message = "stiffness matrix could not be factorized";
      return report;
    }
    Eigen::VectorXd direction = -m_solver.solve(r);
    double slope = r.dot(direction);
    if (!(slope < 0.0)) {
      direction = -r;
      slope = -r.squaredNorm();
    }
    const Eigen::VectorXd step = m_assembly.extend(direction);
    const double energy = total_energy(x);
    double t = 1.0;
    bool accepted = false;
    for (int k = 0; k < 40; ++k, t *= 0.5) {
      const Eigen::VectorXd trial = x + t * step;
      const double trial_energy = total_energy(trial);
      if (!std::isfinite(trial_energy)) continue;
      // Energy decrease (Armijo), or a clear residual decrease where energy differences drown in round-off.
      if (trial_energy <= energy + 1e-4 * t * slope ||
          m_assembly.restrict(residual(trial, pressure_mpa)).norm() < 0.5 * report.residual_norm) {
        x = trial;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      report.stop = NewtonStop::LineSearchFailed;
      report.message = "line search failed";
      return report;
    }
  }
}

NewtonReport EquilibriumSolver::newton_volume(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                                              const NewtonSettings& settings) {
  NewtonReport report;
  const double volume_tolerance = settings.relative_tolerance * std::abs(target_volume);
  auto merit = [&](const Eigen::VectorXd& y, double p, double force_tolerance) {
    const double rn = m_assembly.restrict(residual(y, p)).norm();
    const double c = m_model.volume(y) - target_volume;
    const double value = std::pow(rn / force_tolerance, 2) + std::pow(c / volume_tolerance, 2);
    return std::isfinite(value) ? value : std::numeric_limits<double>::infinity();
  };
  std::vector<double> scaled_residuals;  // |r| / force tolerance per iteration
  double previous_residual = std::numeric_limits<double>::infinity();
  double residual_at_exact_try = std::numeric_limits<double>::infinity();  // N, when the exact step was last tried
  for (report.iterations = 0;; ++report.iterations) {
    const Eigen::VectorXd r = m_assembly.restrict(residual(x, pressure_mpa));
    const double c = m_model.volume(x) - target_volume;
    report.residual_norm = r.norm();
    report.volume_error = c;
    const double scale = force_scale(x, pressure_mpa);
    const double force_tolerance = settings.relative_tolerance * scale;
    if (!std::isfinite(report.residual_norm) || !std::isfinite(c)) {
      report.stop = NewtonStop::NonFinite;
      report.message = "non-finite residual";
      return report;
    }
    const double previous = std::exchange(previous_residual, report.residual_norm);
    if ((std::abs(c) <= volume_tolerance && report.residual_norm <= force_tolerance) ||
        (std::abs(c) <= std::max(volume_tolerance, VOLUME_ROUNDING * std::abs(target_volume)) &&
         at_rounding_floor(x, pressure_mpa, r, previous, scale, report))) {
      report.unstable_modes = m_last_unstable_modes;
      report.converged = true;
      report.stop = NewtonStop::Converged;
      report.message = converged_message(report);
      return report;
    }
    if (report.iterations >= settings.max_iterations) {
      report.stop = NewtonStop::IterationLimit;
      report.message = "Newton iteration limit reached";
      return report;
    }
    if (settings.on_iteration) settings.on_iteration(report.iterations, report.residual_norm, pressure_mpa);
    if (should_stop(settings, report)) return report;
    scaled_residuals.push_back(report.residual_norm / force_tolerance);
    const size_t last = scaled_residuals.size() - 1;
    // Creeping: the residual has not halved over the last `steps` steps.
    auto not_halved_in = [&](size_t steps) {
      return last >= steps && scaled_residuals[last] > 0.5 * scaled_residuals[last - steps];
    };
    if (settings.abandon_slow || settings.stagnation_tolerance_factor > 0.0) {
      if (last >= 4 && not_halved_in(2)) {
        if (scaled_residuals[last] <= settings.stagnation_tolerance_factor && std::abs(c) <= volume_tolerance) {
          report.unstable_modes = m_last_unstable_modes;
          report.converged = true;
          report.stop = NewtonStop::Converged;
          report.stagnated_at = scaled_residuals[last];
          report.message = converged_message(report);
          return report;
        }
        if (settings.abandon_slow) {
          report.stop = NewtonStop::Slow;
          report.message = "converging too slowly";
          return report;
        }
      }
    }
    const Eigen::VectorXd v = m_assembly.restrict(m_model.volume_gradient(x));

    // Fast path: exact Newton on the KKT system; globalised on the residual norm, for which it is a
    // descent direction. Tried at the start, after an exact step, and once the SQP steps below are
    // unshifted (close to a solution), so far from one no factorization is spent on it.
    bool exact = false;
    static const bool debug = std::getenv("BALLOON_DEBUG_NEWTON") != nullptr;
    if (debug)
      std::fprintf(stderr, "vol it %d r=%.3g tol=%.3g c=%.3g p=%.5g shift=%.3g\n", report.iterations,
                   report.residual_norm, force_tolerance, c, pressure_mpa, m_sqp_shift);
    // Also whenever shifted SQP steps have cut the residual tenfold since the last try: they creep where
    // the exact step converges at once (the femur with latex at x27 crept through 50 of them at |r| ~ 3e-3 N
    // and then converged in 3 exact steps).
    const bool exact_worth_trying = report.iterations == 0 || m_last_step_exact || m_sqp_unshifted_steps > 0 ||
                                    report.residual_norm < 0.1 * residual_at_exact_try;
    m_last_step_exact = false;
    const bool exact_tried = exact_worth_trying && m_exact_fails_left == 0;
    if (exact_tried) residual_at_exact_try = report.residual_norm;
    KktSolves solved;
    const bool exact_factorized = exact_tried && factorize_exact_for_volume(x, pressure_mpa, v, r, solved);
    if (exact_factorized) {
      ++report.exact_factorizations;
      if (m_solver.negative_pivots() > 0) ++report.indefinite_factorizations;
    }
    if (exact_factorized && m_last_unstable_modes == 0) {
      // A constrained minimum's inertia (K positive definite, or past a pressure maximum one negative
      // direction that the volume constraint removes): the exact step descends on the augmented
      // Lagrangian, a better guide than the residual norm far from a solution. (Past the maximum the
      // residual norm took the femur at 20 mm, Neo-Hookean x8, through 564 Newton steps; this, 343.)
      exact = constrained_descent(x, pressure_mpa, target_volume, v, r, c, solved, true) >= 0;
      if (!exact) m_exact_fails_left = 2;
    } else if (exact_factorized) {
      const Eigen::VectorXd a = -solved.of_residual;
      const Eigen::VectorXd& b = solved.of_volume_gradient;
      const double vb = v.dot(b);
      if (std::abs(vb) > 0.0) {
        const double dp = (-c - v.dot(a)) / vb;
        // Towards a saddle the step keeps its rigid part: without it, femur's start took 1,500 Newton
        // steps instead of 84.
        const Eigen::VectorXd step = m_assembly.extend(a + dp * b);
        const double merit0 = std::pow(report.residual_norm / force_tolerance, 2) + std::pow(c / volume_tolerance, 2);
        // Here K has unstable modes: the step heads for a saddle (a symmetric state past a bifurcation,
        // as a sphere past its pressure maximum). Only a full step is taken: Newton's own convergence
        // shows the saddle is near; otherwise the SQP step below leaves it for a stable state.
        const Eigen::VectorXd trial = x + step;
        if (merit(trial, pressure_mpa + dp, force_tolerance) <= (1.0 - 1e-4) * merit0) {
          x = trial;
          pressure_mpa += dp;
          exact = true;
        }
      }
      if (!exact) m_exact_fails_left = 2;
    } else if (m_exact_fails_left > 0) {
      --m_exact_fails_left;
    }
    if (exact) {
      m_last_step_exact = true;
      continue;
    }

    // Robust path (wrinkling, snap-through, past limit points, far from a solution): an SQP step on a
    // positive definite model of the Hessian, which descends towards a constrained minimum of W.
    // Near a saddle (the exact step towards it refused) the projected blocks are far stiffer than the
    // sheet along its soft directions, and their unshifted steps can creep: the latex cube's designed rest
    // shape sat at 1e-4 N (2,000 tolerances) for 55 steps at a time, 1,805 Newton steps and 161 s for its
    // path to x8. There the exact Hessian, shifted to a constrained minimum's inertia, is the better model
    // (402 steps, 29 s; the quick bench 2,449 -> 2,238 Newton steps). Used at once near every saddle, it
    // cost more than it saved (knot with latex x27: 73 -> 121 Newton steps).
    const bool creeping_near_saddle =
        settings.exact_hessian_near_saddles && m_last_unstable_modes > 0 &&
        report.residual_norm < NEAR_SADDLE_RESIDUAL * scale && not_halved_in(SADDLE_CREEP_STEPS);
    if (!sqp_step(x, pressure_mpa, target_volume, v, r, c, settings, creeping_near_saddle)) {
      report.stop = NewtonStop::LineSearchFailed;
      report.message = "line search failed";
      return report;
    }
  }
}

bool EquilibriumSolver::factorize_exact_for_volume(const Eigen::VectorXd& x, double pressure_mpa,
                                                   const Eigen::VectorXd& v, const Eigen::VectorXd& r,
                                                   KktSolves& solved) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, false);
  if (!m_exact_indefinite && m_solver.factorize_llt(m_assembly.values()) == SparseSolver::Status::Ok) {
    m_last_unstable_modes = 0;
    solved = solve_kkt(r, v);
    return true;
  }
  if (m_skip_ldlt > 0) {
    --m_skip_ldlt;
    return false;
  }
  if (!factorize_exact_ldlt()) {
    m_skip_ldlt = 2;
    return false;
  }
  // Inertia of the bordered KKT matrix [K v; v^T 0] (Haynsworth): In(K) plus the sign of -v^T K^-1 v.
  // A stable volume-controlled state has exactly one negative eigenvalue there (the constraint's); each
  // more is an unstable direction (a wrinkling or symmetry-breaking mode). Newton still converges to such
  // saddles when started close, and the caller's residual line search decides whether a step is good.
  solved = solve_kkt(r, v);
  m_last_unstable_modes = std::max(0, kkt_negative_eigenvalues(v, solved) - 1);
  return true;
}

EquilibriumSolver::KktSolves EquilibriumSolver::solve_kkt(const Eigen::VectorXd& r, const Eigen::VectorXd& v) const {
  Eigen::MatrixXd rhs(r.size(), 2);
  rhs << r, v;
  const Eigen::MatrixXd solution = m_solver.solve_columns(rhs);
  return {solution.col(0), solution.col(1)};
}

int EquilibriumSolver::kkt_negative_eigenvalues(const Eigen::VectorXd& v, const KktSolves& solved) const {
  return m_solver.negative_pivots() + (v.dot(solved.of_volume_gradient) > 0.0 ? 1 : 0);
}

bool EquilibriumSolver::sqp_step(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                                 const Eigen::VectorXd& v, const Eigen::VectorXd& r, double c,
                                 const NewtonSettings& settings, bool exact_hessian) {
  m_model.assemble_hessian(x, pressure_mpa, m_assembly, !exact_hessian);
  const double base = std::max(1e-30, m_assembly.mean_abs_diagonal());
  // The model H (projected membrane blocks, exact pressure term) is used unshifted when the KKT matrix
  // [H v; v^T 0] has the inertia of a constrained minimum (H positive definite, or one negative
  // direction that the volume constraint removes: past a pressure maximum); otherwise with the
  // smallest Levenberg shift (tried in tenfold steps, kept from step to step) that gives it that inertia.
  // Shifted until positive definite instead, a bulge running along the knot's tube at a nearly constant
  // pressure needed ~0.02 N/mm and crept (1,032 Newton steps against 92).
  // Once a model was indefinite, the next ones go straight to LDL^T (its inertia also tells a positive
  // definite model, which sends the next one back to LL^T): past a pressure maximum the LL^T attempt
  // failed at step after step, each costing about 60% of a factorization (dino, Neo-Hookean: 500 failed
  // attempts, 28% of the factorization time).
  KktSolves solved;
  auto minimum_inertia = [&](double trial_shift) {
    const bool positive_definite =
        !m_sqp_indefinite && m_solver.factorize_llt(m_assembly.values(), trial_shift) == SparseSolver::Status::Ok;
    if (!positive_definite) {
      if (m_solver.factorize_ldlt(m_assembly.values(), trial_shift) != SparseSolver::Status::Ok) return false;
      m_sqp_indefinite = m_solver.negative_pivots() > 0;
    }
    solved = solve_kkt(r, v);
    return positive_definite || kkt_negative_eigenvalues(v, solved) == 1;
  };
  // With settings.shift_after_cut_short, the step after one cut short starts at the raised shift instead
  // of trying the unshifted model first: on the femur at 20 mm (Neo-Hookean x8) that model, nearly
  // singular along the constraint, gave steps of 640 mm cut to 1/2048, step after step.
  double shift = settings.shift_after_cut_short && m_sqp_cut_short ? m_sqp_shift : 0.0;
  bool factorized = minimum_inertia(shift);
  if (!factorized)
    shift = shift > 0.0 ? 10.0 * shift : std::max(settings.shift_restart * m_sqp_shift, 1e-6 * base);
  while (!factorized) {
    if (shift > 1e8 * base) return false;
    factorized = minimum_inertia(shift);
    if (!factorized) shift *= 10.0;
  }
  m_sqp_shift = shift;
  const int halvings = constrained_descent(x, pressure_mpa, target_volume, v, r, c, solved, false);
  if (halvings >= 0) {
    // Cut short more than twice: the shifted model was too bold, so the next one starts stiffer. (Only
    // here: exact steps cut short once raised it too, x4 per step without bound, until a later SQP
    // step found it beyond its limit and failed at once; the knot's start took 40 s instead of 12 s.)
    m_sqp_cut_short = halvings > 2;
    if (m_sqp_cut_short) m_sqp_shift = std::max(m_sqp_shift * 4.0, 1e-6 * base);
    m_sqp_unshifted_steps = shift == 0.0 ? m_sqp_unshifted_steps + 1 : 0;
    return true;
  }
  m_sqp_shift = std::max(m_sqp_shift * 100.0, 1e-4 * base);
  m_sqp_cut_short = true;
  m_sqp_unshifted_steps = 0;
  return true;  // no progress this time; the larger shift shortens the next step
}

int EquilibriumSolver::constrained_descent(Eigen::VectorXd& x, double& pressure_mpa, double target_volume,
                                           const Eigen::VectorXd& v, const Eigen::VectorXd& r, double c,
                                           const KktSolves& solved, bool exact_model) {
  // KKT step of the factorized positive definite model H: H dx - dp v = -r, v.dx = -c.
  const Eigen::VectorXd& a = solved.of_residual;
  const Eigen::VectorXd& b = solved.of_volume_gradient;
  const double vb = v.dot(b);
  if (!(std::abs(vb) > 0.0)) return -1;
  const double dp = (v.dot(a) - c) / vb;
  const Eigen::VectorXd dx = -a + dp * b;
  const double trial_pressure = pressure_mpa + dp;
  const double base = std::max(1e-30, m_assembly.mean_abs_diagonal());
  // Merit: the augmented Lagrangian at the new multiplier; along dx its slope is -dx.H.dx - kappa c^2 < 0.
  const double kappa = base / v.squaredNorm();
  auto merit = [&](const Eigen::VectorXd& y) {
    const double cy = m_model.volume(y) - target_volume;
    return m_model.elastic_energy(y) - trial_pressure * cy + 0.5 * kappa * cy * cy;
  };
  const double slope = (r - dp * v + kappa * c * v).dot(dx);
  const bool floating = exact_model && !m_support.empty();
  Eigen::VectorXd step = m_assembly.extend(dx);
  if (floating) step = without_rigid_motion(x, step);
  const double value = merit(x);
  // Close to a solution the merit's change drowns in the round-off of W; a clear fall of the KKT
  // residual (force and volume, each against its own scale) then decides.
  auto kkt_residual = [&](const Eigen::VectorXd& y, double p) {
    const double force = m_assembly.restrict(residual(y, p)).norm();
    const double volume = (m_model.volume(y) - target_volume) * std::sqrt(kappa) * std::sqrt(base);
    const double norm = std::hypot(force, volume);
    return std::isfinite(norm) ? norm : std::numeric_limits<double>::infinity();
  };
  const double kkt0 = std::hypot(r.norm(), c * std::sqrt(kappa) * std::sqrt(base));
  // A full unshifted SQP step that lowered the merit by more than its quadratic model predicts (half the
  // slope) went along a direction softer than the model, whose membrane blocks are made positive
  // definite: an unstable direction they hide. There the step is doubled while the merit keeps falling.
  // (The anchor at 100 mm, Mooney-Rivlin x2: its walls slid towards each other through 90 full steps
  // with the residual creeping up from 1e-4 N, 237 Newton steps in all; lengthened, 80.) A shifted model
  // was made stiff on purpose and is taken as it is.
  auto lengthened = [&](double full_step_merit) {
    double best = full_step_merit, length = 1.0;
    for (int doubling = 0; doubling < MAX_STEP_DOUBLINGS; ++doubling) {
      const double longer = merit(x + 2.0 * length * step);
      if (!(std::isfinite(longer) && longer < best)) break;
      best = longer;
      length *= 2.0;
    }
    return length;
  };
  double t = 1.0;
  for (int k = 0; k < 30; ++k, t *= 0.5) {
    const Eigen::VectorXd trial = x + t * step;
    const double trial_value = merit(trial);
    if ((std::isfinite(trial_value) && trial_value <= value + 1e-4 * t * std::min(0.0, slope)) ||
        kkt_residual(trial, pressure_mpa + t * dp) < 0.5 * kkt0) {
      const bool softer_than_modelled =
          k == 0 && !exact_model && m_sqp_shift == 0.0 && slope < 0.0 && value - trial_value > 0.75 * -slope;
      const double length = softer_than_modelled ? lengthened(trial_value) : t;
      x += length * step;
      pressure_mpa += length * dp;
      return k;
    }
    if (k == 0 && floating) {
      // Second-order correction (the Maratos effect): a full step along a soft direction can carry a
      // second-order volume error that the merit rejects although the step is good. Taking the full
      // step's own volume error back along K^-1 v costs no solve.
      const double full_step_error = m_model.volume(trial) - target_volume;
      const double dq = -full_step_error / vb;
      const Eigen::VectorXd corrected = trial + dq * without_rigid_motion(x, m_assembly.extend(b));
      const double corrected_value = merit(corrected);
      if ((std::isfinite(corrected_value) && corrected_value <= value + 1e-4 * std::min(0.0, slope)) ||
          kkt_residual(corrected, pressure_mpa + dp + dq) < 0.5 * kkt0) {
        x = corrected;
        pressure_mpa += dp + dq;
        return 0;
      }
    }
  }
  return -1;
}

}  // namespace balloon
