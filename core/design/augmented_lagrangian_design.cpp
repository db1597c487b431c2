#include "design/augmented_lagrangian_design.hpp"

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "design/adjoint_sensitivity.hpp"
#include "design/design_objective.hpp"
#include "design/distance_energy.hpp"
#include "design/surface_distance.hpp"
#include "fem/assembly.hpp"
#include "fem/membrane_element.hpp"
#include "fem/pressure_load.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/sparse_solver.hpp"

namespace balloon {

namespace {

/// The final inflation of the ALM's rest shape may run past the budget by this fraction of it.
constexpr double FINAL_SOLVE_GRACE = 0.25;

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
  /// dC/dx] = [M, K] (the term lambda^T d2C is dropped), assembled through TriangleAssembly and factorized
  /// by SparseSolver (CHOLMOD) on a pattern analysed once, like the forward solver's Newton systems.
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

    prepare_hessian(free);
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
        assemble_hessian(z, pressure, mu);
        // Mean diagonal over all 2n coordinates, the fixed ones counting as 0 (damping scale).
        const double diagonal = m_hessian->mean_abs_diagonal() * m_hessian->free_count() / static_cast<double>(2 * n);
        if (damping == 0.0) damping = 1e-6;
        const bool finite = gradient.allFinite() &&
                            std::all_of(m_hessian->values().begin(), m_hessian->values().end(),
                                        [](double v) { return std::isfinite(v); });
        Eigen::VectorXd direction;
        for (int attempt = 0; attempt < 8; ++attempt) {
          if (finite && m_linear.factorize_llt(m_hessian->values(), damping * diagonal) == SparseSolver::Status::Ok) {
            direction = -m_hessian->extend(m_linear.solve(m_hessian->restrict(gradient)));
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
      m_objective.note_rest_barriers(z.head(n), result);
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
    // Past the budget by at most a quarter of it: a final inflation that diverged ran 13 s past a 40 s
    // budget (generated mitten and tablet, silicone, 4,000 vertices) before it failed.
    if (m_settings.deadline_s > 0)
      settings.deadline_s = std::max(m_settings.deadline_s, design_clock_s()) + FINAL_SOLVE_GRACE * m_options.max_time_s;
    m_model.set_rest_positions(unflatten(rest));
    m_last_report = m_solver.solve_volume(x, inflated_pressure, m_target_volume, settings);
    m_x = x;
    m_pressure = inflated_pressure;
    m_driver.set_final_equilibrium(m_last_report.converged);
    // Optimal held for the ALM iterate, not for the start handed back instead of it.
    auto start_handed_back = [&](const std::string& why) {
      if (result.stop == DesignStop::Optimal) stop_with(result, DesignStop::Stalled, "stalled: " + why);
      else result.message += "; " + why;
    };
    if (!m_last_report.converged) {
      const std::string not_balanced = "the final rest shape did not reach equilibrium (" + m_last_report.message + ")";
      // Its shape would be no balloon's: the start, a true equilibrium, is handed back instead.
      if (m_driver.restore_best_equilibrium(rest)) {
        m_driver.set_final_equilibrium(true);
        start_handed_back(not_balanced + "; the start is handed back");
      } else {
        result.message += "; " + not_balanced;
      }
    } else if (m_driver.restore_best(rest)) {
      // As the adjoint method hands back its best design: the start is a true equilibrium too, and an ALM
      // result that inflates farther from the target is no better design (cactus, latex, 10 s: 3.22 mm
      // against the start's 3.10 mm).
      start_handed_back("its final rest shape inflated farther from the target than the start, which is handed back");
    }
    return m_driver.finish(result, rest);
  }

 private:
  /// The Hessian's pattern over z = (rest, x), as 2#V vertices (rest v is vertex v, inflated v is
  /// vertex #V + v): each vertex's row of J = [M, K] couples its one-ring's rest and inflated coordinates,
  /// so J^T J couples every two of them; the objective's edges and hinges lie within a one-ring too.
  /// Fixed coordinates (`free` false) have no row or column.
  void prepare_hessian(const std::vector<bool>& free) {
    const Faces& faces = m_target.faces;
    const int vertices = m_target.vertex_count();
    m_vertex_faces.assign(static_cast<size_t>(vertices), {});
    m_rings.assign(static_cast<size_t>(vertices), {});
    for (int f = 0; f < faces.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        m_vertex_faces[static_cast<size_t>(faces(f, k))].push_back(f);
        for (int j = 0; j < 3; ++j) m_rings[static_cast<size_t>(faces(f, k))].push_back(faces(f, j));
      }
    }
    std::vector<std::vector<int>> groups(static_cast<size_t>(vertices));
    for (int v = 0; v < vertices; ++v) {
      auto& ring = m_rings[static_cast<size_t>(v)];
      ring.push_back(v);
      std::sort(ring.begin(), ring.end());
      ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
      auto& group = groups[static_cast<size_t>(v)];
      for (int u : ring) group.push_back(u);
      for (int u : ring) group.push_back(vertices + u);
    }
    std::vector<bool> fixed(free.size());
    for (size_t c = 0; c < free.size(); ++c) fixed[c] = !free[c];
    m_hessian = std::make_unique<fem::TriangleAssembly>(groups, 2 * vertices, fixed);
    m_linear.set_pattern(m_hessian->free_count(), m_hessian->column_starts(), m_hessian->row_indices());
  }

  /// Gauss-Newton Hessian of the augmented Lagrangian over z = (rest, x) into m_hessian: mu J^T J with
  /// J = [M, K], one dense one-ring block per vertex's rows of J, plus H_dist^GN(x) on the x block, the
  /// rest-bending Gauss-Newton block when active, and E_surf's.
  void assemble_hessian(const Eigen::VectorXd& z, double pressure, double mu) {
    const Eigen::Index n = z.size() / 2;
    const Faces& faces = m_target.faces;
    const int vertices = m_target.vertex_count();
    const Eigen::VectorXd rest = z.head(n), x = z.tail(n);
    std::vector<fem::Matrix9d> mixed(static_cast<size_t>(faces.rows())), stiffness(static_cast<size_t>(faces.rows()));
    for (int f = 0; f < faces.rows(); ++f) {
      const fem::Vector9d rest_corners = m_model.corners(rest, f), x_corners = m_model.corners(x, f);
      mixed[static_cast<size_t>(f)] =
          fem::membrane_mixed_derivative(m_model.material(), m_model.thickness(f), rest_corners, x_corners);
      double energy = 0.0;
      fem::Vector9d element_gradient;
      fem::membrane_energy_gradient_hessian(m_model.material(), m_model.thickness(f),
                                            fem::make_rest_triangle(rest_corners), x_corners, energy,
                                            element_gradient, stiffness[static_cast<size_t>(f)]);
      stiffness[static_cast<size_t>(f)] -= pressure * fem::triangle_volume_hessian(x_corners);
    }
    m_hessian->set_zero();
    Eigen::MatrixXd jacobian, block;
    std::vector<int> coordinates;
    for (int v = 0; v < vertices; ++v) {
      const std::vector<int>& ring = m_rings[static_cast<size_t>(v)];
      const int m = static_cast<int>(ring.size());
      jacobian.setZero(3, 6 * m);
      for (int f : m_vertex_faces[static_cast<size_t>(v)]) {
        const int k = faces(f, 0) == v ? 0 : faces(f, 1) == v ? 1 : 2;
        for (int j = 0; j < 3; ++j) {
          const int local = static_cast<int>(std::lower_bound(ring.begin(), ring.end(), faces(f, j)) - ring.begin());
          jacobian.block<3, 3>(0, 3 * local) += mixed[static_cast<size_t>(f)].block<3, 3>(3 * k, 3 * j);
          jacobian.block<3, 3>(0, 3 * (m + local)) += stiffness[static_cast<size_t>(f)].block<3, 3>(3 * k, 3 * j);
        }
      }
      // Rows of fixed inflated coordinates are no constraints (their residual is zero).
      for (int a = 0; a < 3; ++a)
        if (m_hessian->free_index(static_cast<int>(n) + 3 * v + a) < 0) jacobian.row(a).setZero();
      block.noalias() = mu * jacobian.transpose() * jacobian;
      coordinates.clear();
      for (int u : ring)
        for (int a = 0; a < 3; ++a) coordinates.push_back(3 * u + a);
      for (int u : ring)
        for (int a = 0; a < 3; ++a) coordinates.push_back(static_cast<int>(n) + 3 * u + a);
      m_hessian->add_block(coordinates, block);
    }
    std::vector<Eigen::Triplet<double>> objective_entries;
    m_distance.hessian_triplets(x, objective_entries, DistanceHessian::GaussNewton, static_cast<int>(n));
    if (m_objective.rest_bending_active())
      m_objective.start_hinges().hessian_triplets(rest, objective_entries, DistanceHessian::GaussNewton, 0);
    m_objective.add_surface_hessian(x, objective_entries, static_cast<int>(n));
    for (const auto& entry : objective_entries) m_hessian->add_entry(entry.row(), entry.col(), entry.value());
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
  std::vector<std::vector<int>> m_vertex_faces;  ///< triangles around each vertex
  std::vector<std::vector<int>> m_rings;         ///< each vertex and its neighbours, sorted
  std::unique_ptr<fem::TriangleAssembly> m_hessian;  ///< Gauss-Newton Hessian over the free z coordinates
  SparseSolver m_linear;                         ///< its LL^T, pattern analysed once
};

}  // namespace

DesignResult run_augmented_lagrangian_design(DesignDriver& driver) { return AugmentedLagrangianDesign(driver).run(); }

}  // namespace balloon
