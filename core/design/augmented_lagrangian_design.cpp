#include "design/augmented_lagrangian_design.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <vector>

#include "design/adjoint_sensitivity.hpp"
#include "design/design_objective.hpp"
#include "design/distance_energy.hpp"
#include "design/surface_distance.hpp"
#include "fem/membrane_element.hpp"
#include "fem/pressure_load.hpp"
#include "solve/equilibrium_solver.hpp"

namespace balloon {

namespace {

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

}  // namespace

DesignResult run_augmented_lagrangian_design(DesignDriver& driver) { return AugmentedLagrangianDesign(driver).run(); }

}  // namespace balloon
