#include "material/fitting.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unsupported/Eigen/NonLinearOptimization>

#include "material/homogeneous_tests.hpp"

namespace balloon {
namespace {

// A residual that cannot be evaluated (overflowing exponential, bulge model that fails) counts as this
// large relative error, so Levenberg-Marquardt rejects the step instead of propagating NaN.
constexpr double UNREACHABLE_RESIDUAL = 1e6;
// log-moduli are clamped so exp() stays finite while the optimizer explores.
constexpr double MAX_LOG_MODULUS = 40.0;

Deformation deformation_of(TestKind kind) {
  switch (kind) {
    case TestKind::Uniaxial: return Deformation::Uniaxial;
    case TestKind::Equibiaxial: return Deformation::Equibiaxial;
    case TestKind::PureShear: return Deformation::PureShear;
    case TestKind::Bulge: break;
  }
  throw std::logic_error("deformation_of: a bulge test is not a homogeneous deformation");
}

int parameter_count(MaterialModel model) { return static_cast<int>(parameter_names(model).size()); }

/// Optimization variables -> physical constants: first a log-modulus, the others squared (>= 0).
Material material_from_variables(MaterialModel model, const Eigen::VectorXd& q) {
  Material m;
  m.model = model;
  m.params[0] = std::exp(std::clamp(q[0], -MAX_LOG_MODULUS, MAX_LOG_MODULUS));
  for (int i = 1; i < q.size(); ++i) m.params[i] = q[i] * q[i];
  return m;
}

Eigen::VectorXd variables_from_material(const Material& m) {
  Eigen::VectorXd q(parameter_count(m.model));
  q[0] = std::log(m.params[0]);
  for (int i = 1; i < q.size(); ++i) q[i] = std::sqrt(std::max(m.params[i], 0.0));
  return q;
}

/// The data side of the least-squares problem: all points of all sets, with their residual weights.
struct Problem {
  MaterialModel model;
  const std::vector<MeasurementSet>* sets;
  const FitOptions* options;
  std::vector<std::vector<double>> weights;  // per set, per point: 1 / max(|y|, floor)
  int points = 0;

  bool cancelled() const { return options->cancel != nullptr && options->cancel->cancelled(); }

  std::vector<double> model_y(const Material& m, size_t s) const {
    const auto& set = (*sets)[s];
    return model_values(m, set, set.x, *options);
  }

  /// Relative residuals (model - data) * weight, all sets stacked; unreachable points get a large value.
  Eigen::VectorXd residuals(const Material& m) const {
    Eigen::VectorXd r(points);
    int k = 0;
    for (size_t s = 0; s < sets->size(); ++s) {
      const auto y = model_y(m, s);
      const auto& set = (*sets)[s];
      for (size_t i = 0; i < set.x.size(); ++i, ++k) {
        const double v = (i < y.size() ? y[i] - set.y[i] : NAN) * weights[s][i];
        r[k] = std::isfinite(v) ? std::clamp(v, -UNREACHABLE_RESIDUAL, UNREACHABLE_RESIDUAL) : UNREACHABLE_RESIDUAL;
      }
    }
    return r;
  }
};

/// Levenberg-Marquardt functor over the optimization variables; Jacobian by central differences.
struct LmFunctor {
  const Problem* problem;
  int* evaluations;
  int inputs() const { return parameter_count(problem->model); }
  int values() const { return problem->points; }
  int operator()(const Eigen::VectorXd& q, Eigen::VectorXd& fvec) const {
    if (problem->cancelled()) return -1;  // Levenberg-Marquardt stops with UserAsked
    ++*evaluations;
    fvec = problem->residuals(material_from_variables(problem->model, q));
    return 0;
  }
  int df(const Eigen::VectorXd& q, Eigen::MatrixXd& fjac) const {
    if (problem->cancelled()) return -1;
    fjac.resize(values(), inputs());
    for (int j = 0; j < q.size(); ++j) {
      const double h = 1e-6 * std::max(1.0, std::abs(q[j]));
      Eigen::VectorXd qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      *evaluations += 2;
      fjac.col(j) = (problem->residuals(material_from_variables(problem->model, qp)) -
                     problem->residuals(material_from_variables(problem->model, qm))) /
                    (2.0 * h);
    }
    return 0;
  }
};

/// Candidate shapes for the coarse start grid: constants with the leading modulus set to 1 MPa.
std::vector<Material> start_shapes(MaterialModel model) {
  std::vector<Material> shapes;
  Material m;
  m.model = model;
  switch (model) {
    case MaterialModel::NeoHookean:
      m.params = {1.0, 0.0, 0.0};
      shapes.push_back(m);
      break;
    case MaterialModel::MooneyRivlin:
      // C2 = 0 exactly would sit where the squared variable has zero gradient; 0.01 C1 starts near it.
      for (double ratio : {0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0}) {
        m.params = {1.0, ratio, 0.0};
        shapes.push_back(m);
      }
      break;
    case MaterialModel::HartSmith:
      for (double k1 : {1e-6, 1e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1})
        for (double k2 : {1e-3, 0.1, 0.3, 1.0, 3.0, 10.0}) {
          m.params = {1.0, k1, k2};
          shapes.push_back(m);
        }
      break;
  }
  return shapes;
}

/// Every model response is linear in the leading modulus when the dimensionless constants are fixed (the
/// whole energy scales with it), so the best modulus for a shape is a weighted linear least-squares fit.
/// Returns the scaled material and its cost (sum of squared relative residuals), or infinite cost.
std::pair<Material, double> best_scale(const Problem& problem, Material shape) {
  double fy = 0.0, ff = 0.0;
  std::vector<std::vector<double>> f(problem.sets->size());
  for (size_t s = 0; s < problem.sets->size(); ++s) {
    f[s] = problem.model_y(shape, s);
    const auto& set = (*problem.sets)[s];
    for (size_t i = 0; i < set.x.size(); ++i) {
      const double w2 = problem.weights[s][i] * problem.weights[s][i];
      if (i >= f[s].size() || !std::isfinite(f[s][i])) return {shape, std::numeric_limits<double>::infinity()};
      fy += f[s][i] * set.y[i] * w2;
      ff += f[s][i] * f[s][i] * w2;
    }
  }
  if (!(ff > 0.0) || !(fy > 0.0)) return {shape, std::numeric_limits<double>::infinity()};
  const double scale = fy / ff;
  shape.params[0] *= scale;
  if (shape.model == MaterialModel::MooneyRivlin) shape.params[1] *= scale;  // C2 is a modulus too
  double cost = 0.0;
  for (size_t s = 0; s < problem.sets->size(); ++s) {
    const auto& set = (*problem.sets)[s];
    for (size_t i = 0; i < set.x.size(); ++i) {
      const double r = (scale * f[s][i] - set.y[i]) * problem.weights[s][i];
      cost += r * r;
    }
  }
  return {shape, cost};
}

/// Jacobian of the relative residuals w.r.t. the physical constants, by central differences (forward
/// differences for a constant at its bound 0, so no negative constant is ever evaluated).
Eigen::MatrixXd physical_jacobian(const Problem& problem, const Material& m, int* evaluations) {
  const int n = parameter_count(m.model);
  Eigen::MatrixXd J(problem.points, n);
  const Eigen::VectorXd r0 = problem.residuals(m);
  for (int j = 0; j < n; ++j) {
    const double h = 1e-5 * std::abs(m.params[j]) + 1e-9;
    Material plus = m, minus = m;
    plus.params[j] += h;
    if (m.params[j] - h > 0.0) {
      minus.params[j] -= h;
      J.col(j) = (problem.residuals(plus) - problem.residuals(minus)) / (2.0 * h);
      *evaluations += 2;
    } else {
      J.col(j) = (problem.residuals(plus) - r0) / h;
      *evaluations += 1;
    }
  }
  return J;
}

std::string status_text(int status) {
  switch (status) {
    case 1: return "converged (relative reduction of the sum of squares below tolerance)";
    case 2: return "converged (relative change of the parameters below tolerance)";
    case 3: return "converged (sum of squares and parameters both within tolerance)";
    case 4: return "converged (residual orthogonal to the Jacobian)";
    case 5: return "not converged: evaluation limit reached (best point found is returned)";
    case 6: return "converged (no further reduction of the sum of squares possible)";
    case 7: return "converged (no further improvement of the parameters possible)";
    case 8: return "converged (gradient at machine precision)";
    default: return "not converged: solver status " + std::to_string(status);
  }
}

std::vector<double> regime_transform(TestKind kind, const std::vector<double>& x, std::vector<double> y) {
  if (kind == TestKind::Equibiaxial)
    for (size_t i = 0; i < y.size(); ++i) y[i] /= x[i] * x[i];  // balloon curve p ~ P_ET(l) / l^2
  return y;
}

}  // namespace

std::vector<double> spherical_cap_bulge_pressures(const Material& material, const MeasurementSet& set) {
  const double a = set.disc_radius_mm, H = set.thickness_mm;
  std::vector<double> p(set.x.size(), 0.0);
  for (size_t i = 0; i < set.x.size(); ++i) {
    const double rho = set.x[i];
    const double t = std::sqrt(std::max(rho * rho - 1.0, 0.0));  // h / a
    if (t < 1e-12) continue;                                       // flat disc holds no pressure
    const double cap_radius = a * (1.0 + t * t) / (2.0 * t);
    const double l = rho;
    p[i] = 1e3 * 2.0 * H * nominal_stress(material, Deformation::Equibiaxial, l) / (l * cap_radius);  // MPa -> kPa
  }
  return p;
}

Regimes detect_regimes(const std::vector<double>& x, const std::vector<double>& y) {
  Regimes regimes;
  const size_t n = std::min(x.size(), y.size());
  if (n < 3) return regimes;
  const double range = x[n - 1] - x[0];
  if (!(range > 0.0)) return regimes;
  const double width = 0.25 * range;
  constexpr int WINDOWS = 13;
  std::vector<double> slopes;
  for (int k = 0; k < WINDOWS; ++k) {
    const double center = x[0] + 0.5 * width + k * (range - width) / (WINDOWS - 1);
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      if (std::abs(x[i] - center) > 0.5 * width * (1.0 + 1e-9)) continue;
      sx += x[i];
      sy += y[i];
      sxx += x[i] * x[i];
      sxy += x[i] * y[i];
      ++count;
    }
    const double denominator = count * sxx - sx * sx;
    if (count < 2 || !(denominator > 1e-14 * count * sxx)) continue;
    slopes.push_back((count * sxy - sx * sy) / denominator);
  }
  if (slopes.size() < 3) return regimes;
  const auto min_it = std::min_element(slopes.begin(), slopes.end());
  const double s_min = *min_it, s_first = slopes.front(), s_last = slopes.back();
  double largest = 0.0;
  for (double s : slopes) largest = std::max(largest, std::abs(s));
  const double tol = 0.05 * largest;
  const bool interior = min_it != slopes.begin() && min_it != slopes.end() - 1;
  regimes.inflection = interior && s_first - s_min > tol && s_last - s_min > tol;
  regimes.stiffening = s_last > 0.0 && s_last - s_min > tol;
  return regimes;
}

std::vector<double> regime_curve(const MeasurementSet& set) { return regime_transform(set.kind, set.x, set.y); }

std::vector<double> model_values(const Material& material, const MeasurementSet& set, const std::vector<double>& x,
                                 const FitOptions& options) {
  if (set.kind == TestKind::Bulge) {
    MeasurementSet query = set;
    // The model must not look at the data: the pressures go; the apex heights are abscissae of the data
    // points (a model may prefer them to extension ratios), so they stay only at the data's own points.
    const bool at_data_points = x == set.x;
    query.x = x;
    query.y.assign(x.size(), 0.0);
    if (!at_data_points) query.apex_height_mm.clear();
    return options.bulge_model ? options.bulge_model(material, query) : spherical_cap_bulge_pressures(material, query);
  }
  std::vector<double> y(x.size());
  const auto deformation = deformation_of(set.kind);
  for (size_t i = 0; i < x.size(); ++i) y[i] = nominal_stress(material, deformation, x[i]);
  return y;
}

Result<FitResult> fit_material(MaterialModel model, const std::vector<MeasurementSet>& sets, const FitOptions& options) {
  if (sets.empty()) return fail("no measurements to fit");
  Problem problem{model, &sets, &options, {}, 0};
  for (const auto& set : sets) {
    if (auto problem_text = measurement_problem(set); !problem_text.empty())
      return fail((set.label.empty() ? std::string("measurements") : set.label) + ": " + problem_text);
    double largest = 0.0;
    for (double v : set.y) largest = std::max(largest, std::abs(v));
    if (!(largest > 0.0)) return fail((set.label.empty() ? std::string("measurements") : set.label) + ": all values are zero");
    const double floor = std::max(options.relative_floor, 1e-12) * largest;
    std::vector<double> w;
    for (double v : set.y) w.push_back(1.0 / std::max(std::abs(v), floor));
    problem.weights.push_back(std::move(w));
    problem.points += static_cast<int>(set.x.size());
  }
  const int n = parameter_count(model);
  if (problem.points < n)
    return fail("only " + std::to_string(problem.points) + " data points for the " + std::to_string(n) + " parameters of " +
                model_name(model));

  FitResult result;
  result.points = problem.points;

  // Coarse grid of shapes, each with its best modulus; the best few start Levenberg-Marquardt.
  std::vector<std::pair<Material, double>> candidates;
  for (const auto& shape : start_shapes(model)) {
    auto scaled = best_scale(problem, shape);
    result.evaluations += 1;
    if (std::isfinite(scaled.second)) candidates.push_back(scaled);
  }
  if (candidates.empty()) return fail("no starting point of " + model_name(model) + " reproduces the data's sign (are the values positive?)");
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  candidates.resize(std::min<size_t>(candidates.size(), static_cast<size_t>(std::max(options.starts, 1))));

  LmFunctor functor{&problem, &result.evaluations};
  double best_cost = std::numeric_limits<double>::infinity();
  Material best = candidates.front().first;
  int best_status = -1;
  for (const auto& candidate : candidates) {
    if (problem.cancelled()) return fail(FIT_CANCELLED);
    Eigen::VectorXd q = variables_from_material(candidate.first);
    Eigen::LevenbergMarquardt<LmFunctor> lm(functor);
    lm.parameters.maxfev = options.max_evaluations;
    const int status = static_cast<int>(lm.minimize(q));
    const Material fitted = material_from_variables(model, q);
    const double cost = problem.residuals(fitted).squaredNorm();
    result.evaluations += 1;
    if (cost < best_cost) {
      best_cost = cost;
      best = fitted;
      best_status = status;
    }
  }
  if (problem.cancelled()) return fail(FIT_CANCELLED);
  result.material = best;
  result.converged = best_status >= 1 && best_status <= 8 && best_status != 5;
  std::ostringstream message;
  message << status_text(best_status) << "; " << candidates.size() << " starts";
  const auto names = parameter_names(model);
  for (int j = 1; j < n; ++j)
    if (best.params[j] < 1e-8 * std::max(1.0, best.params[0]))
      message << "; " << names[j] << " is at its bound 0";

  // Residuals, absolute (data units) and relative (the fitted quantity), per set and overall.
  const Eigen::VectorXd r = problem.residuals(best);
  double abs_sq = 0.0;
  bool has_stress = false, has_bulge = false;
  int k = 0;
  for (size_t s = 0; s < sets.size(); ++s) {
    const auto& set = sets[s];
    SetFit fit;
    fit.label = set.label;
    fit.kind = set.kind;
    fit.points = static_cast<int>(set.x.size());
    fit.dropped_compression_points = set.dropped_compression_points;
    fit.residual_unit = set.kind == TestKind::Bulge ? "kPa" : "MPa";
    (set.kind == TestKind::Bulge ? has_bulge : has_stress) = true;
    const auto y = problem.model_y(best, s);
    double set_abs_sq = 0.0, set_rel_sq = 0.0;
    for (size_t i = 0; i < set.x.size(); ++i, ++k) {
      const double a = std::abs(y[i] - set.y[i]);
      set_abs_sq += a * a;
      fit.max_residual = std::max(fit.max_residual, a);
      set_rel_sq += r[k] * r[k];
      fit.max_relative_residual = std::max(fit.max_relative_residual, std::abs(r[k]));
    }
    fit.rms_residual = std::sqrt(set_abs_sq / fit.points);
    fit.rms_relative_residual = std::sqrt(set_rel_sq / fit.points);
    abs_sq += set_abs_sq;
    result.max_residual = std::max(result.max_residual, fit.max_residual);
    result.max_relative_residual = std::max(result.max_relative_residual, fit.max_relative_residual);

    fit.data_regimes = detect_regimes(set.x, regime_curve(set));
    const int grid_points = std::max(options.regime_grid_points, 3);
    std::vector<double> grid(grid_points);
    for (int g = 0; g < grid_points; ++g) grid[g] = set.x.front() + (set.x.back() - set.x.front()) * g / (grid_points - 1);
    fit.model_regimes = detect_regimes(grid, regime_transform(set.kind, grid, model_values(best, set, grid, options)));
    result.sets.push_back(fit);
  }
  result.rms_residual = std::sqrt(abs_sq / problem.points);
  result.rms_relative_residual = std::sqrt(best_cost / problem.points);
  result.residual_unit = has_stress && has_bulge ? "mixed" : has_bulge ? "kPa" : "MPa";

  size_t headline = 0;
  const auto find_kind = [&](TestKind kind) {
    for (size_t s = 0; s < sets.size(); ++s)
      if (sets[s].kind == kind) return static_cast<int>(s);
    return -1;
  };
  if (int b = find_kind(TestKind::Bulge); b >= 0) headline = b;
  else if (int e = find_kind(TestKind::Equibiaxial); e >= 0) headline = e;
  result.data_inflection = result.sets[headline].data_regimes.inflection;
  result.data_stiffening = result.sets[headline].data_regimes.stiffening;
  result.model_inflection = result.sets[headline].model_regimes.inflection;
  result.model_stiffening = result.sets[headline].model_regimes.stiffening;

  // Standard errors from the linearized problem in physical units: cov = s^2 (J^T J)^-1.
  if (problem.points > n) {
    const Eigen::MatrixXd J = physical_jacobian(problem, best, &result.evaluations);
    const double s2 = best_cost / (problem.points - n);
    // Columns equilibrated first, so the rank test compares like with like (G ~ 0.1 MPa next to
    // k1 ~ 1e-3) and a constant at its bound 0 is not mistaken for an unidentifiable one.
    Eigen::VectorXd scale(n);
    for (int j = 0; j < n; ++j) {
      const double norm = J.col(j).norm();
      scale[j] = norm > 0.0 ? 1.0 / norm : 1.0;
    }
    const Eigen::MatrixXd Js = J * scale.asDiagonal();
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Js.transpose() * Js);
    lu.setThreshold(1e-12);
    if (lu.isInvertible()) {
      const Eigen::MatrixXd cov = s2 * scale.asDiagonal() * lu.inverse() * scale.asDiagonal();
      for (int j = 0; j < n; ++j) result.std_errors.push_back(std::sqrt(std::max(cov(j, j), 0.0)));
    } else {
      result.std_errors.assign(n, std::numeric_limits<double>::infinity());
      message << "; parameters not all identifiable from these data";
    }
  }
  result.message = message.str();
  return result;
}

}  // namespace balloon
