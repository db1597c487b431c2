#include "design/reduced_space_design.hpp"

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "design/adjoint_sensitivity.hpp"
#include "design/design_objective.hpp"
#include "design/distance_energy.hpp"
#include "design/lbfgs.hpp"
#include "design/reduced_gauss_newton.hpp"
#include "design/surface_distance.hpp"
#include "design/trust_radius.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon {

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
/// Conjugate-gradient iterations (two solves each, no factorization) and relative residual of one
/// Gauss-Newton direction.
constexpr int GAUSS_NEWTON_CG_ITERATIONS = 20;
constexpr double GAUSS_NEWTON_CG_TOLERANCE = 1e-2;
/// The largest move of any rest vertex in one design step, a fraction of the target's diagonal.
constexpr double MAX_TRUST_RADIUS_REL = 0.02;
/// Past a pressure maximum, the design iterations made while its check from rest runs on another thread.
constexpr int ITERATIONS_BESIDE_CHECK = 1;

/// A fraction as a short human string: 0.01 -> "1%", 1e-4 -> "1e-04".
std::string format_fraction(double fraction) {
  char text[32];
  if (fraction >= 0.01) std::snprintf(text, sizeof(text), "%g%%", 100.0 * fraction);
  else std::snprintf(text, sizeof(text), "%.0e", fraction);
  return text;
}

/// Why a design within MATCH_TOLERANCE_REL of its target stopped.
std::string matched_message() {
  return "matched: the inflated shape matches the target to " + format_fraction(MATCH_TOLERANCE_REL) +
         " of its bounding-box diagonal";
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
        m_all_rest_free(std::all_of(m_rest_free.begin(), m_rest_free.end(), [](bool free) { return free; })),
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
    if (m_options.resume && m_driver.resume_from(*m_options.resume, rest, result)) {
      result.resumed_from_iteration = m_options.resume->iteration;
      first_iteration = m_options.resume->iteration + 1;
      const SurfaceDistanceStats resumed = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
      m_driver.record(result, m_options.resume->iteration, resumed, rest);
      m_driver.remember_if_best(rest, resumed.avg_mm);
      stall_reference = resumed.avg_mm;
      m_objective.grow_surface_weight(m_options.resume->iteration);  // where the interrupted design had it
      m_driver.debug_time("resumed from the checkpoint");
    }
    // A start that already matches (a regular icosahedron inflates onto itself) is done: with nothing left
    // to descend, the first line search would otherwise fail and call the match a stall.
    if (stall_reference < MATCH_TOLERANCE_REL * result.bbox_diag_mm) {
      stop_with(result, DesignStop::Matched, matched_message());
      return m_driver.finish(result, rest);
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
    int small_decreases = 0;
    double stall_objective = objective;         // objective at the last real improvement of either
    int stall_iteration = first_iteration - 1;
    TrustRadius trust(MAX_TRUST_RADIUS_REL * result.bbox_diag_mm);
    int check_iteration = 0;  // the iteration whose rest shape the running check from rest inflates
    bool gauss_newton_failed = false;  // the last line search, along Gauss-Newton, accepted no step
    bool stagnated = false;            // the current equilibrium was accepted where Newton stagnated
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
      // The check from rest started at the last growth has run beside the iteration since; its verdict.
      if (m_driver.shape_from_rest_pending() && iteration - check_iteration > ITERATIONS_BESIDE_CHECK &&
          m_driver.take_pending_shape_from_rest(rest)) {
        // What the radius learned on the branch left behind says nothing about this one: shrunk there
        // (latex bear: seven halvings in one iteration), it took eight iterations to grow back.
        trust.start_over();
        gauss_newton_failed = false;  // another equilibrium, another Gauss-Newton model
        stagnated = false;
        m_objective.realign(m_x);
        const SurfaceDistanceStats reached = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
        m_driver.remember_if_best(rest, reached.avg_mm);
        stall_reference = reached.avg_mm;
        stall_iteration = iteration;
        m_driver.debug_time("took the shape reached from rest");
        objective = m_objective.value(rest, m_x);
        stall_objective = objective;
        m_lbfgs.clear();
        if (!objective_gradient(rest, gradient)) {
          stop_with(result, DesignStop::Stalled, "stalled: the design gradient is not finite");
          break;
        }
        build_preconditioner();
      }
      // Gauss-Newton in the reduced space first; L-BFGS where it gives no descent direction, or once its
      // line search failed: from the same point the Gauss-Newton direction is the same one (its CG uses only
      // the fixed preconditioner), so trying it again repeated the same failed trials.
      const GaussNewtonDirection gauss_newton =
          gauss_newton_failed ? GaussNewtonDirection{} : gauss_newton_direction(rest, gradient);
      gauss_newton_failed = false;
      m_driver.debug_time("gauss-newton direction");
      const bool newton_like = gauss_newton.descent;
      Eigen::VectorXd direction = gauss_newton.direction;
      if (!newton_like) {
        direction = -m_lbfgs.apply(gradient);
        for (int c = 0; c < direction.size(); ++c)
          if (!m_rest_free[static_cast<size_t>(c)]) direction[c] = 0.0;
        if (!(direction.dot(gradient) < 0.0)) {
          m_lbfgs.clear();
          direction = -gradient;
        }
      }
      // Every term is blind to rigid motions of the rest shape, so a direction's rigid part (what the
      // Gauss-Newton model's null space and its preconditioner leave in) gains nothing, but spends the trust
      // radius and turns the balloon about its pinned coordinates: latex cactus's trials crept from the
      // first iteration on and it stalled at the baseline; without it, 4.9-7.6x. A nozzle pins the rest shape.
      if (m_all_rest_free) direction = without_rigid_motion(rest, direction);
      // Trust region on the rest shape: no vertex moves more than the radius (at most 2% of the target's
      // size) per step, so a wrinkling region costs one failed equilibrium, not one per iteration.
      const double largest = unflatten(direction).rowwise().norm().maxCoeff();
      double t = largest > trust.radius() ? trust.radius() / largest : 1.0;
      const double first_t = t;
      if (!newton_like && m_lbfgs.empty()) t = std::min(t, 0.002 * result.bbox_diag_mm / std::max(largest, 1e-300));
      const double slope = direction.dot(gradient);
      // First-order response of the equilibrium to the rest step, from the factorization the gradient
      // just used: each trial starts Newton a second-order distance from its solution.
      Eigen::VectorXd response;
      double pressure_response = 0.0;
      m_sensitivity.linear_response(direction, response, pressure_response);
      m_driver.debug_time("linear response");
      bool accepted = false, bending_switched = false;
      int balanced_trials = 0;        // trials whose rest shape reached an equilibrium
      std::string unbalanced_reason;  // why the last trial that did not reached none
      Eigen::VectorXd trial_rest, trial_x;
      double trial_pressure = 0.0, trial_objective = 0.0;
      for (int k = 0; k < 12; ++k, t *= 0.5) {
        trial_rest = m_driver.keep_rest_volume(rest + t * direction, m_driver.rest_volume(rest));
        trial_x = m_x + t * response;
        trial_pressure = m_pressure + t * pressure_response;
        if (!m_driver.trial_start_in_range(trial_rest, trial_x, trial_pressure)) {
          if (design_debug())
            std::fprintf(stderr, "  it %d trial %d t=%.3g: the predictor is out of range\n", iteration, k, t);
          unbalanced_reason = "its first-order start out of range";
          continue;
        }
        const bool balanced = m_driver.equilibrium(trial_rest, trial_x, trial_pressure);
        if (design_debug())
          std::fprintf(stderr, "  it %d trial %d t=%.3g newton %d %s (%.2f s)\n", iteration, k, t,
                       m_last_report.iterations, m_last_report.message.c_str(), design_clock_s() - m_driver.start_time());
        if (!balanced) {
          if (m_driver.stopped()) break;
          unbalanced_reason = m_last_report.message;
          // A step into compression with no stable membrane state: the real sheet's bending gives those
          // regions one. Switched on once; the iteration then starts over from the same rest shape.
          if (creeping_through_wrinkles(m_last_report) && m_driver.switch_bending_on(rest, result)) {
            bending_switched = true;
            break;
          }
          continue;
        }
        ++balanced_trials;
        trial_objective = m_objective.value(trial_rest, trial_x);
        if (design_debug())
          std::fprintf(stderr, "    objective %.9g -> %.9g (change %.3g, asked %.3g, first order %.3g)\n", objective,
                       trial_objective, trial_objective - objective, 1e-4 * t * slope, t * slope);
        if (trial_objective <= objective + 1e-4 * t * slope) {
          accepted = true;
          break;
        }
      }
      if (bending_switched) {
        stagnated = false;
        if (!restart_at_equilibrium(rest, objective, gradient)) {
          stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized");
          break;
        }
        --iteration;  // no step was taken
        continue;
      }
      if (!accepted) {
        if (m_driver.stopped()) {
          stop_with(result, m_last_report.message == "cancelled" ? DesignStop::Cancelled : DesignStop::TimeLimit,
                    m_last_report.message);
          break;
        }
        // An equilibrium accepted where Newton stagnated can stand by a saddle, rolling off it: every trial
        // from it then rolled off to a stable neighbour, higher in the objective (silicone cactus: 12 trials
        // from t = 1e-6 down to 4e-10 all ended 3-5% higher, and the design stalled at 11.1x after 17
        // iterations). Taken on to the tolerance itself, the design goes on from there (the cactus: 41
        // iterations in its 40 s, 16.4x). Settling every such trial as it was accepted did as well there,
        // but spent 30 Newton steps on each that did not settle, where no line search had failed.
        if (stagnated && m_driver.settle(rest)) {
          stagnated = false;
          if (!restart_at_equilibrium(rest, objective, gradient)) {
            stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized");
            break;
          }
          m_driver.debug_time("settled");
          continue;
        }
        // Steepest descent next: L-BFGS's curvature pairs may be stale, and Gauss-Newton would be the same again.
        if (newton_like || !m_lbfgs.empty()) {
          gauss_newton_failed = newton_like;
          m_lbfgs.clear();
          continue;
        }
        // A failed line search is optimality only where the gradient has vanished; elsewhere it is a stall
        // (a wrinkling region no trial step could balance, say), and says so.
        if (gradient.norm() <= OPTIMALITY_TOLERANCE * initial_gradient_norm) {
          stop_with(result, DesignStop::Optimal, "optimal: the design gradient fell below " +
                                                     format_fraction(OPTIMALITY_TOLERANCE) + " of its start value");
        } else if (balanced_trials == 0) {
          stop_with(result, DesignStop::Stalled,
                    "stalled: no rest shape along the steepest descent reached an equilibrium (" +
                        unbalanced_reason + "; design gradient at " +
                        format_ratio(gradient.norm() / initial_gradient_norm) + " its start value)");
        } else {
          stop_with(result, DesignStop::Stalled,
                    "stalled: no decrease along the steepest descent (design gradient at " +
                        format_ratio(gradient.norm() / initial_gradient_norm) + " its start value)");
        }
        break;
      }
      const double model_decrease = gauss_newton_model_decrease(t, slope);
      const double agreement = model_decrease > 0.0 ? (objective - trial_objective) / model_decrease : 1.0;
      if (design_debug())
        std::fprintf(stderr, "    step: gauss-newton %d, largest move %.3g mm at t = 1, radius %.3g mm, agreement %.3g\n",
                     newton_like ? 1 : 0, largest, trust.radius(), agreement);
      trust.after_step(first_t, t, largest, agreement, newton_like);
      stagnated = m_last_report.stagnated_at > 0.0;
      const Eigen::VectorXd step = trial_rest - rest;
      rest = trial_rest;
      m_x = trial_x;
      m_pressure = trial_pressure;
      const bool collisions_changed = m_objective.update_collisions(rest, result);
      m_objective.note_rest_barriers(rest, result);
      // Re-placed on the target after every step (vertex correspondence, the result's placement). E_surf
      // is taken at that placement (rigid-invariant, as E_dist is), so no term changes; when it was taken
      // at the pinned placement, E_surf fought E_dist for it (a matchable target stalled at 4e-4 of its
      // size), and each re-placement undid what the step had gained (latex blobby: 2-9% of the objective).
      m_objective.realign(m_x);
      Eigen::VectorXd new_gradient;
      // The line search already evaluated this point; only a changed set of colliding pairs alters it.
      objective = collisions_changed ? m_objective.value(rest, m_x) : trial_objective;
      if (!objective_gradient(rest, new_gradient)) {
        stop_with(result, DesignStop::Stalled, "stalled: the adjoint system could not be factorized");
        break;
      }
      m_driver.debug_time("gradient");
      const Eigen::VectorXd change = new_gradient - gradient;
      m_lbfgs.update(step, change);
      gradient = new_gradient;
      const SurfaceDistanceStats stats = m_surface.aligned_stats(unflatten(m_x), m_target.vertices);
      m_driver.record(result, iteration, stats, rest);
      m_driver.remember_if_best(rest, stats.avg_mm);
      result.iterations = iteration;
      m_driver.debug_time("surface error");
      const double relative_decrease = -t * slope / std::max(initial_objective, 1e-300);
      small_decreases = relative_decrease < 1e-7 ? small_decreases + 1 : 0;
      if (stats.avg_rel < MATCH_TOLERANCE_REL) {
        stop_with(result, DesignStop::Matched, matched_message());
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
      if (m_objective.grow_surface_weight(iteration)) {
        // A new objective: its value, gradient, preconditioner and curvature pairs start over. The count
        // towards a stall goes on: a design whose error no growth moves is still stalled.
        // Past a pressure maximum a rubber has several equilibria at one volume, and the branch this design
        // follows as it reshapes the rest shape need not be the one a maker reaches by inflating it from
        // rest (latex corpus, 40 s: 6 of 18 designs ended 5-9 mm from that shape, 0.6-0.9x the baseline
        // from rest). So at each growth the rest shape is inflated from rest as balloon simulate does, and
        // the design goes on from that shape where it is another one (from rest: 5/18 -> 7/18 within 1% and
        // 3x, median 2.05% -> 1.28%). That holds where the design's own state is stable under pressure
        // (dV/dp > 0) too: the generated latex jack's was, yet it matched on its own branch and reached
        // 6.8 mm from rest (1.0x the baseline); checked at every growth, 19.7x from rest. Silicone corpus,
        // checked only past the maximum against at every growth: from rest 14/18, 17/18 with both, median
        // 0.263% -> 0.255%, the knot no longer on another shape (1.0x -> 1.8x), 0-10 fewer iterations.
        // That inflation runs on a thread of its own beside the next iteration, and the design then takes
        // its verdict; where it switches, that iteration (on the other branch) is given up. Latex corpus,
        // 40 s, against the check in the design's own thread: 1-9 more iterations on 17 of 18 shapes, 12
        // closer to the target from rest (spot 15.9x -> 18.1x, the retinal blob 4.8x -> 7.0x), 2 farther.
        // Taken when ready instead, or with a check always running, the verdicts came later, more designs
        // ended on another shape, and fewer reached the target (README "Design on the corpus", session 61).
        if (!m_driver.shape_from_rest_pending()) {
          m_driver.start_shape_from_rest(rest, iteration);
          check_iteration = iteration;
        }
        objective = m_objective.value(rest, m_x);
        m_lbfgs.clear();
        if (!gradient_at_prepared(rest, gradient)) {
          stop_with(result, DesignStop::Stalled, "stalled: the design gradient is not finite");
          break;
        }
        build_preconditioner();
        stall_objective = objective;
        m_driver.debug_time("surface term grown");
        continue;
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
        m_lbfgs.clear();
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
  /// The equilibrium of the same rest shape changed (the sheet's bending switched on, or settled): the
  /// objective, its gradient and the curvature pairs start over there. False where the adjoint system
  /// could not be factorized.
  bool restart_at_equilibrium(const Eigen::VectorXd& rest, double& objective, Eigen::VectorXd& gradient) {
    m_objective.realign(m_x);
    objective = m_objective.value(rest, m_x);
    m_lbfgs.clear();
    return objective_gradient(rest, gradient);
  }

  /// d objective / d rest through the adjoint of the bordered equilibrium system at (m_x, m_pressure):
  /// [K -v; -v^T 0] [lambda; mu] = [dE/dx; 0], gradient = -(d grad_x W / d rest)^T lambda.
  bool objective_gradient(const Eigen::VectorXd& rest, Eigen::VectorXd& gradient) {
    m_model.set_rest_positions(unflatten(rest));
    if (!m_sensitivity.prepare(rest, m_x, m_pressure)) return false;
    return gradient_at_prepared(rest, gradient);
  }

  /// objective_gradient with the sensitivity already prepared at (rest, m_x, m_pressure): after the
  /// objective itself changed there.
  bool gradient_at_prepared(const Eigen::VectorXd& rest, Eigen::VectorXd& gradient) {
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

  /// The Gauss-Newton direction at the current equilibrium (the sensitivity was prepared by the last
  /// objective_gradient): E_dist's and E_surf's Gauss-Newton Hessian in inflated coordinates, pulled back.
  GaussNewtonDirection gauss_newton_direction(const Eigen::VectorXd& rest, const Eigen::VectorXd& gradient) {
    const ObjectiveGaussNewton hessian = m_objective.gauss_newton(m_x);
    return reduced_gauss_newton_direction(
        m_sensitivity, hessian, gradient, m_rest_free, m_model.volume_gradient(rest),
        [this](const Eigen::VectorXd& q) { return m_lbfgs.precondition(q); }, GAUSS_NEWTON_CG_ITERATIONS,
        GAUSS_NEWTON_CG_TOLERANCE,
        [this, &rest](const Eigen::VectorXd& d) { return m_objective.regularizer_gauss_newton_times(rest, d); });
  }

  /// L-BFGS's initial inverse Hessian: the Gauss-Newton Hessian of E_dist at the start's inflation,
  /// factorized once. The rest-to-inflated map is close to a scaling, so this is the shape of the
  /// objective's curvature in rest coordinates; L-BFGS corrects the rest.
  void build_preconditioner() {
    std::vector<Eigen::Triplet<double>> entries;
    // Room for both terms at once: about 2 million entries at 4,000 vertices, which the surface term's
    // few more doubled (a 70 MB copy beside the 35 MB one, the design's peak memory) when they did not fit.
    entries.reserve(m_distance.hessian_entry_count() + 9 * static_cast<size_t>(m_x.size() / 3));
    m_distance.hessian_triplets(m_x, entries, DistanceHessian::GaussNewton);
    m_objective.add_surface_hessian(m_x, entries, 0);
    Eigen::SparseMatrix<double> hessian(m_x.size(), m_x.size());
    hessian.setFromTriplets(entries.begin(), entries.end());
    m_lbfgs.set_preconditioner(std::move(hessian));
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
  const bool m_all_rest_free;  ///< no nozzle holds rest vertices
  const double m_target_volume;
  Eigen::VectorXd& m_x;           ///< the driver's current equilibrium
  double& m_pressure;
  NewtonReport& m_last_report;
  Lbfgs m_lbfgs{30};  ///< L-BFGS on the rest shape: (s, y) pairs of the last 30 accepted steps
};

}  // namespace

DesignResult run_reduced_space_design(DesignDriver& driver) { return ReducedSpaceDesign(driver).run(); }

}  // namespace balloon
