#include "design/balloon_design.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <optional>

#include "design/adjoint_sensitivity.hpp"
#include "design/design_driver.hpp"
#include "design/design_objective.hpp"
#include "design/distance_energy.hpp"
#include "design/surface_distance.hpp"
#include "fem/balloon_model.hpp"
#include "fem/membrane_element.hpp"
#include "fem/pressure_load.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon {

std::string design_method_name(DesignMethod method) {
  return method == DesignMethod::Adjoint ? "adjoint" : "alm";
}

std::string design_stop_name(DesignStop stop) {
  switch (stop) {
    case DesignStop::Matched: return "matched";
    case DesignStop::Optimal: return "optimal";
    case DesignStop::Stalled: return "stalled";
    case DesignStop::TimeLimit: return "time_limit";
    case DesignStop::IterationLimit: return "iteration_limit";
    case DesignStop::StartFailed: return "start_failed";
    case DesignStop::Cancelled: return "cancelled";
  }
  return "stalled";
}

Result<DesignMethod> parse_design_method(const std::string& name) {
  if (name == "adjoint") return DesignMethod::Adjoint;
  if (name == "alm") return DesignMethod::AugmentedLagrangian;
  return fail("unknown design method '" + name + "' (known: adjoint, alm)");
}

namespace {

/// The adjoint method stops when neither the average surface error (what the maker sees) nor the
/// objective has improved by STALL_IMPROVEMENT (relative) in STALL_ITERATIONS iterations, or when the
/// average error is below MATCH_TOLERANCE_REL of the target's diagonal (0.01 mm on 100 mm, far below
/// what a 3D printer or a brushed silicone layer reproduces).
constexpr double STALL_IMPROVEMENT = 0.01;
constexpr int STALL_ITERATIONS = 15;
/// While the objective still falls by this much per STALL_ITERATIONS, a design whose error rose for a
/// while (reshaping a perturbed start) is not stalled.
constexpr double STALL_OBJECTIVE_DECREASE = 0.1;
constexpr double MATCH_TOLERANCE_REL = 1e-4;
/// First-order optimality: the design gradient below this fraction of its value at the start.
constexpr double OPTIMALITY_TOLERANCE = 1e-6;

/// A fraction as a short human string: 0.01 -> "1%", 1e-4 -> "1e-04".
std::string format_fraction(double fraction) {
  char text[32];
  if (fraction >= 0.01) std::snprintf(text, sizeof(text), "%g%%", 100.0 * fraction);
  else std::snprintf(text, sizeof(text), "%.0e", fraction);
  return text;
}

/// A ratio as a short human string: 131.4 -> "131x", 0.002 -> "0.002x".
std::string format_ratio(double ratio) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3gx", ratio);
  return text;
}

/// Reduced-space design: the inflated shape x is the volume-controlled equilibrium of the rest shape,
/// warm-started from the previous one; the gradient of E_dist(x(rest)) comes from one adjoint solve of
/// the bordered equilibrium system with the Hessian factorized at the equilibrium; L-BFGS outside.
class ReducedSpaceDesign {
 public:
  explicit ReducedSpaceDesign(DesignDriver& driver)
      : m_driver(driver),
        m_target(driver.target()),
        m_options(driver.options()),
        m_model(driver.model()),
        m_solver(driver.solver()),
        m_sensitivity(driver.sensitivity()),
        m_objective(driver.objective()),
        m_distance(driver.objective().distance()),
        m_surface(driver.objective().surface()),
        m_settings(driver.settings()),
        m_rest_free(driver.rest_free()),
        m_target_volume(driver.target_volume()),
        m_x(driver.x()),
        m_pressure(driver.pressure()),
        m_last_report(driver.last_report()) {}

  DesignResult run() {
    DesignResult result = m_driver.begin(DesignMethod::Adjoint);
    result.active_terms.push_back("fixed_rest_volume");

    // Start: inflate the downscaled target to the target's volume; that fixes the inflation.
    Eigen::VectorXd rest = flat(m_driver.start().vertices);
    if (!m_driver.inflate_start(rest, result)) return m_driver.finish(result, rest);
    int first_iteration = 1;
    double stall_reference = *result.baseline_avg_error_mm;  // best surface error at the last real improvement (mm)
    if (m_options.resume && m_driver.resume_from(*m_options.resume, rest)) {
      result.resumed_from_iteration = m_options.resume->iteration;
      first_iteration = m_options.resume->iteration + 1;
      const SurfaceDistanceStats resumed = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
      m_driver.record(result, m_options.resume->iteration, resumed, rest);
      m_driver.remember_if_best(rest, resumed.avg_mm);
      stall_reference = resumed.avg_mm;
      m_driver.debug_time("resumed from the checkpoint");
    }
    Eigen::VectorXd gradient;
    double objective = m_objective.value(rest, m_x);
    if (!objective_gradient(rest, gradient)) {
      stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized at the start");
      return m_driver.finish(result, rest);
    }
    const double initial_gradient_norm = gradient.norm();
    const double initial_objective = objective;
    build_preconditioner();
    m_driver.debug_time("first gradient and preconditioner");
    std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>> memory;  // (s, y) pairs for L-BFGS
    int small_decreases = 0;
    double stall_objective = objective;         // objective at the last real improvement of either
    int stall_iteration = first_iteration - 1;
    const double max_radius = 0.02 * result.bbox_diag_mm;  // mm
    double radius = max_radius;
    stop_with(result, DesignStop::IterationLimit, "iteration limit reached");
    for (int iteration = first_iteration; iteration <= m_options.max_iterations; ++iteration) {
      if (m_options.cancel && m_options.cancel->cancelled()) {
        stop_with(result, DesignStop::Cancelled, "cancelled");
        break;
      }
      if (m_settings.deadline_s > 0 && design_clock_s() > m_settings.deadline_s) {
        stop_with(result, DesignStop::TimeLimit, "time limit reached");
        break;
      }
      Eigen::VectorXd direction = -lbfgs_apply(memory, gradient);
      for (int c = 0; c < direction.size(); ++c)
        if (!m_rest_free[static_cast<size_t>(c)]) direction[c] = 0.0;
      if (!(direction.dot(gradient) < 0.0)) {
        memory.clear();
        direction = -gradient;
      }
      // Trust region on the rest shape: no vertex moves more than `radius` (at most 2% of the target's
      // size) per step. The radius shrinks to the last step that needed halving and grows back after
      // full steps, so a wrinkling region costs one failed equilibrium, not one per iteration.
      const double largest = unflatten(direction).rowwise().norm().maxCoeff();
      double t = largest > radius ? radius / largest : 1.0;
      const double first_t = t;
      if (memory.empty()) t = std::min(t, 0.002 * result.bbox_diag_mm / std::max(largest, 1e-300));
      const double slope = direction.dot(gradient);
      // First-order response of the equilibrium to the rest step, from the factorization the gradient
      // just used: each trial starts Newton a second-order distance from its solution.
      Eigen::VectorXd response;
      double pressure_response = 0.0;
      m_sensitivity.linear_response(direction, response, pressure_response);
      bool accepted = false;
      Eigen::VectorXd trial_rest, trial_x;
      double trial_pressure = 0.0, trial_objective = 0.0;
      for (int k = 0; k < 12; ++k, t *= 0.5) {
        trial_rest = m_driver.keep_rest_volume(rest + t * direction, m_driver.rest_volume(rest));
        trial_x = m_x + t * response;
        trial_pressure = m_pressure + t * pressure_response;
        const bool balanced = m_driver.equilibrium(trial_rest, trial_x, trial_pressure);
        if (std::getenv("BALLOON_DEBUG_DESIGN"))
          std::fprintf(stderr, "  it %d trial %d t=%.3g newton %d %s (%.2f s)\n", iteration, k, t,
                       m_last_report.iterations, m_last_report.message.c_str(), design_clock_s() - m_driver.start_time());
        if (!balanced) {
          if (m_driver.stopped()) break;
          continue;
        }
        trial_objective = m_objective.value(trial_rest, trial_x);
        if (trial_objective <= objective + 1e-4 * t * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        if (m_driver.stopped()) {
          stop_with(result, m_last_report.message == "cancelled" ? DesignStop::Cancelled : DesignStop::TimeLimit,
                    m_last_report.message);
          break;
        }
        if (!memory.empty()) {  // a stale curvature model: restart from steepest descent
          memory.clear();
          continue;
        }
        // A failed line search is optimality only where the gradient has vanished; elsewhere it is a stall
        // (a wrinkling region no trial step could balance, say), and says so.
        if (gradient.norm() <= OPTIMALITY_TOLERANCE * initial_gradient_norm) {
          stop_with(result, DesignStop::Optimal, "optimal: the design gradient fell below " +
                                                     format_fraction(OPTIMALITY_TOLERANCE) + " of its start value");
        } else {
          stop_with(result, DesignStop::Stalled,
                    "stalled: no decrease along the steepest descent (design gradient at " +
                        format_ratio(gradient.norm() / initial_gradient_norm) + " its start value)");
        }
        break;
      }
      radius = t < first_t ? t * largest : std::min(max_radius, 2.0 * radius);
      const Eigen::VectorXd step = trial_rest - rest;
      rest = trial_rest;
      m_x = trial_x;
      m_pressure = trial_pressure;
      const bool collisions_changed = m_objective.update_collisions(rest, result);
      Eigen::VectorXd new_gradient;
      // The line search already evaluated this point; only a changed set of colliding pairs alters it.
      objective = collisions_changed ? m_objective.value(rest, m_x) : trial_objective;
      if (!objective_gradient(rest, new_gradient)) {
        stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized");
        break;
      }
      m_driver.debug_time("gradient");
      const Eigen::VectorXd change = new_gradient - gradient;
      if (step.dot(change) > 1e-12 * step.norm() * change.norm()) {
        memory.emplace_back(step, change);
        if (memory.size() > 30) memory.pop_front();
      }
      gradient = new_gradient;
      const SurfaceDistanceStats stats = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
      m_driver.record(result, iteration, stats, rest);
      m_driver.remember_if_best(rest, stats.avg_mm);
      result.iterations = iteration;
      m_driver.debug_time("surface error");
      const double relative_decrease = -t * slope / std::max(initial_objective, 1e-300);
      small_decreases = relative_decrease < 1e-7 ? small_decreases + 1 : 0;
      if (stats.avg_rel < MATCH_TOLERANCE_REL) {
        stop_with(result, DesignStop::Matched, "matched: the inflated shape matches the target to " +
                                                   format_fraction(MATCH_TOLERANCE_REL) + " of its bounding-box diagonal");
        break;
      }
      if (objective <= 1e-14 * initial_objective || gradient.norm() <= OPTIMALITY_TOLERANCE * initial_gradient_norm) {
        stop_with(result, DesignStop::Optimal, "optimal: the design gradient fell below " +
                                                   format_fraction(OPTIMALITY_TOLERANCE) + " of its start value");
        break;
      }
      if (small_decreases >= 3) {
        stop_with(result, DesignStop::Stalled, "stalled: the objective fell by less than 1e-7 in 3 iterations");
        break;
      }
      if (stats.avg_mm < (1.0 - STALL_IMPROVEMENT) * stall_reference) {
        stall_reference = stats.avg_mm;
        stall_iteration = iteration;
        stall_objective = objective;
      } else if (objective < (1.0 - STALL_OBJECTIVE_DECREASE) * stall_objective) {
        stall_iteration = iteration;  // the error may rise for a while as the objective reshapes the balloon
        stall_objective = objective;
      } else if (iteration - stall_iteration >= STALL_ITERATIONS && m_objective.realign(m_x)) {
        // The pinned coordinates held the shape where the start put it; re-placed on the target, the
        // surface term can pull again. A rigid motion of an equilibrium is one: only the gauge changed.
        memory.clear();
        stall_iteration = iteration;
        objective = m_objective.value(rest, m_x);
        stall_objective = objective;
        if (!objective_gradient(rest, gradient)) {
          stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized");
          break;
        }
      } else if (iteration - stall_iteration >= STALL_ITERATIONS) {
        stop_with(result, DesignStop::Stalled, "stalled: the surface error improved less than " +
                                                   format_fraction(STALL_IMPROVEMENT) + " in the last " +
                                                   std::to_string(STALL_ITERATIONS) + " iterations");
        break;
      }
    }
    m_driver.restore_best(rest);
    return m_driver.finish(result, rest);
  }

 private:
  /// d objective / d rest through the adjoint of the bordered equilibrium system at (m_x, m_pressure):
  /// [K -v; -v^T 0] [lambda; mu] = [dE/dx; 0], gradient = -(d grad_x W / d rest)^T lambda.
  bool objective_gradient(const Eigen::VectorXd& rest, Eigen::VectorXd& gradient) {
    m_model.set_rest_positions(unflatten(rest));
    if (!m_sensitivity.prepare(rest, m_x, m_pressure)) return false;
    gradient = m_sensitivity.gradient(m_objective.shape_gradient(m_x));
    m_objective.add_regularizer_gradient(rest, gradient);
    for (int c = 0; c < gradient.size(); ++c)
      if (!m_rest_free[static_cast<size_t>(c)]) gradient[c] = 0.0;
    // The rest volume stays at target volume / volume ratio: with the inflated volume fixed, a uniform
    // change of rest size barely changes the inflated shape, so without this the asked-for inflation
    // would drift. Project out the rest-volume gradient.
    Eigen::VectorXd w = m_model.volume_gradient(rest);
    for (int c = 0; c < w.size(); ++c)
      if (!m_rest_free[static_cast<size_t>(c)]) w[c] = 0.0;
    gradient -= (gradient.dot(w) / w.squaredNorm()) * w;
    return gradient.allFinite();
  }

  /// L-BFGS's initial inverse Hessian: the Gauss-Newton Hessian of E_dist at the start's inflation,
  /// factorized once. The rest-to-inflated map is close to a scaling, so this is the shape of the
  /// objective's curvature in rest coordinates; L-BFGS corrects the rest.
  void build_preconditioner() {
    std::vector<Eigen::Triplet<double>> entries;
    m_distance.hessian_triplets(m_x, entries, DistanceHessian::GaussNewton);
    m_objective.add_surface_hessian(m_x, entries, 0);
    Eigen::SparseMatrix<double> hessian(m_x.size(), m_x.size());
    hessian.setFromTriplets(entries.begin(), entries.end());
    const double shift = 1e-3 * hessian.diagonal().mean();
    for (int c = 0; c < hessian.rows(); ++c) hessian.coeffRef(c, c) += shift;
    m_preconditioner = std::make_unique<Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>>>(hessian);
    if (m_preconditioner->info() != Eigen::Success) m_preconditioner.reset();
  }

  Eigen::VectorXd precondition(const Eigen::VectorXd& q) const {
    if (!m_preconditioner) return q;
    Eigen::VectorXd r = m_preconditioner->solve(q);
    return r.allFinite() ? r : q;
  }

  Eigen::VectorXd lbfgs_apply(const std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>>& memory,
                              const Eigen::VectorXd& gradient) const {
    Eigen::VectorXd q = gradient;
    std::vector<double> alpha(memory.size());
    for (int i = static_cast<int>(memory.size()) - 1; i >= 0; --i) {
      const auto& [s, y] = memory[static_cast<size_t>(i)];
      alpha[static_cast<size_t>(i)] = s.dot(q) / y.dot(s);
      q -= alpha[static_cast<size_t>(i)] * y;
    }
    q = precondition(q);
    if (!memory.empty()) {
      const auto& [s, y] = memory.back();
      q *= s.dot(y) / y.dot(precondition(y));
    }
    for (size_t i = 0; i < memory.size(); ++i) {
      const auto& [s, y] = memory[i];
      const double beta = y.dot(q) / y.dot(s);
      q += (alpha[i] - beta) * s;
    }
    return q;
  }

  DesignDriver& m_driver;
  const TriMesh& m_target;
  const DesignOptions& m_options;
  fem::BalloonModel& m_model;
  EquilibriumSolver& m_solver;
  AdjointSensitivity& m_sensitivity;
  DesignObjective& m_objective;
  const DistanceEnergy& m_distance;
  const SurfaceDistance& m_surface;
  const NewtonSettings& m_settings;
  const std::vector<bool>& m_rest_free;
  const double m_target_volume;
  Eigen::VectorXd& m_x;           ///< the driver's current equilibrium
  double& m_pressure;
  NewtonReport& m_last_report;
  std::unique_ptr<Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>>> m_preconditioner;
};

class AugmentedLagrangianDesign {
 public:
  explicit AugmentedLagrangianDesign(DesignDriver& driver)
      : m_driver(driver),
        m_target(driver.target()),
        m_options(driver.options()),
        m_model(driver.model()),
        m_solver(driver.solver()),
        m_sensitivity(driver.sensitivity()),
        m_objective(driver.objective()),
        m_distance(driver.objective().distance()),
        m_surface(driver.objective().surface()),
        m_settings(driver.settings()),
        m_rest_free(driver.rest_free()),
        m_target_volume(driver.target_volume()),
        m_x(driver.x()),
        m_pressure(driver.pressure()),
        m_last_report(driver.last_report()) {}

  /// The paper's method (sec. 5.2): minimise E_dist(x) + R(rest) - lambda^T C + mu/2 |C|^2 over rest and
  /// inflated positions together, C = grad_x W(x; rest) - p grad V(x) the nodal force balance at the
  /// start's pressure p (R: the active regularizers). Multipliers update by eq. 22 when |C| fell to a
  /// quarter, else mu grows tenfold. The inner solve is Gauss-Newton with Levenberg-Marquardt damping and
  /// a backtracking line search: the Hessian is approximated by H_dist^GN + mu J^T J with J = [dC/drest,
  /// dC/dx] = [M, K] (the term lambda^T d2C is dropped), factorized by CHOLMOD on a pattern analysed once.
  /// At the end the rest shape is inflated properly, so the reported errors are a true equilibrium's.
  DesignResult run() {
    DesignResult result = m_driver.begin(DesignMethod::AugmentedLagrangian);
    Eigen::VectorXd rest = flat(m_driver.start().vertices);
    if (!m_driver.inflate_start(rest, result)) return m_driver.finish(result, rest);

    const Eigen::Index n = rest.size();
    std::vector<bool> free(static_cast<size_t>(2 * n));
    for (Eigen::Index c = 0; c < n; ++c) {
      free[static_cast<size_t>(c)] = m_rest_free[static_cast<size_t>(c)];
      free[static_cast<size_t>(n + c)] = m_solver.assembly().free_index(static_cast<int>(c)) >= 0;
    }
    const double pressure = m_pressure;
    const double force_scale = m_solver.force_scale(m_x, pressure);
    const double start_distance = std::max(m_distance.value(m_x), 1e-6 * result.bbox_diag_mm);
    double mu = 10.0 * start_distance / (force_scale * force_scale);
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd z(2 * n);
    z << rest, m_x;
    auto constraints = [&](const Eigen::VectorXd& zz) {
      m_model.set_rest_positions(unflatten(zz.head(n)));
      return m_solver.residual(zz.tail(n), pressure);
    };
    auto lagrangian = [&](const Eigen::VectorXd& zz, Eigen::VectorXd* gradient) {
      const Eigen::VectorXd c = constraints(zz);
      Eigen::VectorXd surface_gradient;
      const double value = m_distance.value(zz.tail(n)) +
                           m_objective.surface_term(zz.tail(n), gradient ? &surface_gradient : nullptr) +
                           m_objective.regularizer_value(zz.head(n)) - lambda.dot(c) + 0.5 * mu * c.squaredNorm();
      if (gradient) {
        const Eigen::VectorXd w = mu * c - lambda;
        Eigen::VectorXd distance_gradient;
        m_distance.gradient(zz.tail(n), distance_gradient);
        distance_gradient += surface_gradient;
        gradient->resize(2 * n);
        gradient->head(n) = m_sensitivity.mixed_product(zz.head(n), zz.tail(n), w, true);
        m_objective.add_regularizer_gradient(zz.head(n), gradient->head(n));
        gradient->tail(n) = distance_gradient + m_solver.stiffness_times(zz.tail(n), pressure, w);
        for (Eigen::Index c2 = 0; c2 < 2 * n; ++c2)
          if (!free[static_cast<size_t>(c2)]) (*gradient)[c2] = 0.0;
      }
      return value;
    };

    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> factorization;
    bool analysed = false;
    double damping = 0.0;  // Levenberg-Marquardt, relative to the mean diagonal
    int iteration = 0;
    double constraint_norm = constraints(z).norm();
    stop_with(result, DesignStop::IterationLimit, "iteration limit reached");
    for (int outer = 0; outer < 30 && iteration < m_options.max_iterations; ++outer) {
      Eigen::VectorXd gradient;
      double value = lagrangian(z, &gradient);
      const double inner_tolerance = 1e-3 * gradient.norm();
      for (int inner = 0; inner < 20 && iteration < m_options.max_iterations; ++inner) {
        if (m_options.cancel && m_options.cancel->cancelled()) stop_with(result, DesignStop::Cancelled, "cancelled");
        if (m_settings.deadline_s > 0 && design_clock_s() > m_settings.deadline_s)
          stop_with(result, DesignStop::TimeLimit, "time limit reached");
        if (result.stop != DesignStop::IterationLimit) break;
        ++iteration;
        Eigen::SparseMatrix<double> hessian = gauss_newton_hessian(z, pressure, mu, free);
        const double diagonal = hessian.diagonal().mean();
        if (damping == 0.0) damping = 1e-6;
        Eigen::VectorXd direction;
        for (int attempt = 0; attempt < 8; ++attempt) {
          Eigen::SparseMatrix<double> damped = hessian;
          for (Eigen::Index c = 0; c < damped.rows(); ++c) damped.coeffRef(c, c) += damping * diagonal;
          if (!analysed) {
            factorization.analyzePattern(damped);
            analysed = true;
          }
          factorization.factorize(damped);
          if (factorization.info() == Eigen::Success) {
            direction = -factorization.solve(gradient);
            if (direction.allFinite() && direction.dot(gradient) < 0.0) break;
          }
          direction.resize(0);
          damping *= 10.0;
        }
        if (direction.size() == 0) {
          stop_with(result, DesignStop::Stalled, "stalled: the Gauss-Newton system could not be factorized");
          break;
        }
        // Trust region: no vertex moves more than 2% of the target's size per step.
        const double largest = std::max(unflatten(direction.head(n)).rowwise().norm().maxCoeff(),
                                        unflatten(direction.tail(n)).rowwise().norm().maxCoeff());
        double t = std::min(1.0, 0.02 * result.bbox_diag_mm / std::max(largest, 1e-300));
        const double slope = direction.dot(gradient);
        bool accepted = false;
        for (int k = 0; k < 20 && !accepted; ++k) {
          const Eigen::VectorXd trial = z + t * direction;
          const double trial_value = lagrangian(trial, nullptr);
          if (std::isfinite(trial_value) && trial_value <= value + 1e-4 * t * slope) {
            z = trial;
            value = lagrangian(z, &gradient);
            accepted = true;
          } else {
            t *= 0.5;
          }
        }
        damping = accepted && t == 1.0 ? std::max(1e-9, damping * 0.3) : damping * 10.0;
        if (accepted) {
          m_x = z.tail(n);
          m_pressure = pressure;
          m_last_report.residual_norm = constraints(z).norm();
          const SurfaceDistanceStats stats = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
          m_driver.record(result, iteration, stats, z.head(n));
        }
        if (!accepted || gradient.norm() <= inner_tolerance) break;
      }
      if (result.stop != DesignStop::IterationLimit) break;
      m_objective.update_max_volume_term(z.head(n), start_distance, result);
      const Eigen::VectorXd c = constraints(z);
      const double new_norm = c.norm();
      if (new_norm <= 0.25 * constraint_norm || new_norm <= 1e-6 * force_scale) {
        lambda -= mu * c;  // eq. 22
        constraint_norm = new_norm;
      } else {
        mu *= 10.0;
      }
      lagrangian(z, &gradient);
      if (new_norm <= 1e-6 * force_scale && gradient.norm() < 1e-4 * force_scale) {
        stop_with(result, DesignStop::Optimal,
                  "optimal: force residual below 1e-6 and Lagrangian gradient below 1e-4 of the force scale");
        break;
      }
    }
    result.iterations = iteration;
    // The ALM iterate only nearly balances the forces: report the true equilibrium of its rest shape.
    rest = z.head(n);
    Eigen::VectorXd x = z.tail(n);
    double inflated_pressure = pressure;
    NewtonSettings settings = m_settings;
    settings.deadline_s = 0.0;
    m_model.set_rest_positions(unflatten(rest));
    m_last_report = m_solver.solve_volume(x, inflated_pressure, m_target_volume, settings);
    m_x = x;
    m_pressure = inflated_pressure;
    m_driver.set_final_equilibrium(m_last_report.converged);
    if (!m_last_report.converged)
      result.message += "; the final rest shape did not reach equilibrium (" + m_last_report.message + ")";
    return m_driver.finish(result, rest);
  }

 private:
  /// Gauss-Newton Hessian of the augmented Lagrangian over z = (rest, x): H_dist^GN(x) on the x block,
  /// the rest-bending Gauss-Newton block when active, plus mu J^T J with J = [M, K]. Fixed coordinates
  /// get zero rows and columns (the damping makes them identity).
  Eigen::SparseMatrix<double> gauss_newton_hessian(const Eigen::VectorXd& z, double pressure, double mu,
                                                   const std::vector<bool>& free) const {
    const Eigen::Index n = z.size() / 2;
    const Faces& faces = m_target.faces;
    std::vector<Eigen::Triplet<double>> jacobian_entries;
    jacobian_entries.reserve(static_cast<size_t>(faces.rows()) * 162);
    const Eigen::VectorXd rest = z.head(n), x = z.tail(n);
    for (int f = 0; f < faces.rows(); ++f) {
      const fem::Vector9d rest_corners = m_model.corners(rest, f), x_corners = m_model.corners(x, f);
      const fem::Matrix9d mixed =
          fem::membrane_mixed_derivative(m_model.material(), m_model.thickness(f), rest_corners, x_corners);
      double energy = 0.0;
      fem::Vector9d element_gradient;
      fem::Matrix9d stiffness;
      fem::membrane_energy_gradient_hessian(m_model.material(), m_model.thickness(f),
                                            fem::make_rest_triangle(rest_corners), x_corners, energy,
                                            element_gradient, stiffness);
      stiffness -= pressure * fem::triangle_volume_hessian(x_corners);
      for (int i = 0; i < 9; ++i) {
        const Eigen::Index row = 3 * faces(f, i / 3) + i % 3;
        if (!free[static_cast<size_t>(n + row)]) continue;
        for (int j = 0; j < 9; ++j) {
          const Eigen::Index column = 3 * faces(f, j / 3) + j % 3;
          if (free[static_cast<size_t>(column)]) jacobian_entries.emplace_back(row, column, mixed(i, j));
          if (free[static_cast<size_t>(n + column)]) jacobian_entries.emplace_back(row, n + column, stiffness(i, j));
        }
      }
    }
    Eigen::SparseMatrix<double> jacobian(n, 2 * n);
    jacobian.setFromTriplets(jacobian_entries.begin(), jacobian_entries.end());
    Eigen::SparseMatrix<double> hessian = mu * Eigen::SparseMatrix<double>(jacobian.transpose() * jacobian);
    std::vector<Eigen::Triplet<double>> objective_entries;
    m_distance.hessian_triplets(z.tail(n), objective_entries, DistanceHessian::GaussNewton, static_cast<int>(n));
    if (m_objective.rest_bending_active())
      m_objective.start_hinges().hessian_triplets(z.head(n), objective_entries, DistanceHessian::GaussNewton, 0);
    m_objective.add_surface_hessian(z.tail(n), objective_entries, static_cast<int>(n));
    std::vector<Eigen::Triplet<double>> kept;
    kept.reserve(objective_entries.size());
    for (const auto& entry : objective_entries)
      if (free[static_cast<size_t>(entry.row())] && free[static_cast<size_t>(entry.col())]) kept.push_back(entry);
    Eigen::SparseMatrix<double> objective(2 * n, 2 * n);
    objective.setFromTriplets(kept.begin(), kept.end());
    hessian += objective;
    // Every diagonal entry exists, so the damping adds to the pattern the analysis saw.
    Eigen::SparseMatrix<double> identity(2 * n, 2 * n);
    identity.setIdentity();
    hessian += 0.0 * identity;
    return hessian;
  }

  DesignDriver& m_driver;
  const TriMesh& m_target;
  const DesignOptions& m_options;
  fem::BalloonModel& m_model;
  EquilibriumSolver& m_solver;
  AdjointSensitivity& m_sensitivity;
  DesignObjective& m_objective;
  const DistanceEnergy& m_distance;
  const SurfaceDistance& m_surface;
  const NewtonSettings& m_settings;
  const std::vector<bool>& m_rest_free;
  const double m_target_volume;
  Eigen::VectorXd& m_x;           ///< the driver's current equilibrium
  double& m_pressure;
  NewtonReport& m_last_report;
};

std::string options_problem(const TriMesh& target, const DesignOptions& options) {
  if (target.vertex_count() < 4 || target.face_count() < 4) return "the target mesh is empty";
  if (auto problem = material_problem(options.material); !problem.empty()) return problem;
  if (!(options.thickness_mm > 0.0) || !std::isfinite(options.thickness_mm)) return "thickness must be positive (mm)";
  if (options.scale > 0) {
    if (!(options.scale < 1.0)) return "scale must be below 1: the balloon starts smaller than the target";
  } else if (!(options.volume_ratio > 1.0) || !std::isfinite(options.volume_ratio)) {
    return "volume ratio must be a number above 1";
  }
  if (!(enclosed_volume(target.vertices, target.faces) > 0.0)) return "the target encloses no positive volume";
  if (!(options.k_length >= 0.0 && options.k_bending >= 0.0 && options.k_surface >= 0.0) ||
      !std::isfinite(options.k_length + options.k_bending + options.k_surface))
    return "the objective's weights must be finite and not negative";
  if (options.initial_rest.rows() != 0) {
    if (options.initial_rest.rows() != target.vertex_count() || !options.initial_rest.allFinite())
      return "the initial rest shape must have one finite position per target vertex";
    if (!(enclosed_volume(options.initial_rest, target.faces) > 0.0))
      return "the initial rest shape encloses no positive volume";
  }
  for (int v : options.nozzle_vertices)
    if (v < 0 || v >= target.vertex_count()) return "nozzle vertex " + std::to_string(v) + " does not exist";
  return "";
}

}  // namespace

DesignResult design_balloon(const TriMesh& target, const DesignOptions& options) {
  if (auto problem = options_problem(target, options); !problem.empty()) {
    DesignResult result;
    result.method = options.method;
    result.stop = DesignStop::StartFailed;
    result.message = problem;
    result.rest = target;
    result.inflated = target.vertices;
    return result;
  }
  DesignDriver driver(target, options);
  if (options.method == DesignMethod::AugmentedLagrangian) return AugmentedLagrangianDesign(driver).run();
  return ReducedSpaceDesign(driver).run();
}

}  // namespace balloon
