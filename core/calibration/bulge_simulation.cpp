#include "calibration/bulge_simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "fem/balloon_model.hpp"
#include "solve/equilibrium_solver.hpp"

namespace balloon {
namespace {

constexpr double MPA_PER_KPA = 1e-3;
constexpr double PI = std::numbers::pi;
/// Extension ratio of the spherical cap used as the first shape: the flat disc itself cannot start Newton
/// (a flat membrane has no stiffness out of its plane, so the Hessian is singular there).
constexpr double FIRST_EXTENSION_RATIO = 1.002;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Volume-controlled continuation on one disc mesh. The rim is held; the enclosed volume is the volume
/// between the membrane and the rim plane z = 0 (the cone volume about the origin, which lies in that plane).
class BulgeRun {
 public:
  explicit BulgeRun(const BulgeTestOptions& options)
      : m_options(options),
        m_rest(bulge_disc_mesh(options.radius_mm, options.rings)),
        m_model(m_rest, options.material, std::vector<double>(static_cast<size_t>(m_rest.face_count()), options.thickness_mm)),
        m_fixed(fixed_coordinates(options.rings, m_rest.vertex_count())),
        m_solver(m_model, m_fixed) {
    m_settings.relative_tolerance = options.residual_tolerance;
    m_settings.max_iterations = options.max_newton_iterations;
  }

  bool started() const { return m_started; }
  double volume() const { return m_volume; }
  double pressure_mpa() const { return m_pressure; }

  /// Advances along the volume path to `target` (> current volume), halving steps that fail.
  bool advance_to_volume(double target, std::string& message) {
    if (!m_started && !start(std::min(target, cap_volume(FIRST_EXTENSION_RATIO)), message)) return false;
    double step = m_step;
    while (m_volume < target * (1 - 1e-14)) {
      const double next = std::min(target, m_volume + step);
      NewtonReport report;
      if (volume_step(next, report)) {
        if (report.iterations <= 6) step *= 2.0;
        continue;
      }
      step *= 0.5;
      if (step < 1e-6 * target) {
        message = "no equilibrium found at volume " + std::to_string(next) + " mm^3 (" + report.message + ")";
        return false;
      }
    }
    m_step = step;
    return true;
  }

  /// Solves at the exact pressure from the state interpolated between `previous` and the current one.
  bool solve_at_pressure(const Eigen::VectorXd& previous_x, double previous_pressure, double target, std::string& message) {
    const double theta = (target - previous_pressure) / (m_pressure - previous_pressure);
    Eigen::VectorXd x = previous_x + theta * (m_x - previous_x);
    const NewtonReport report = m_solver.solve_pressure(x, target, m_settings);
    m_iterations += report.iterations;
    if (!report.converged) {
      message = "no equilibrium found at " + std::to_string(target / MPA_PER_KPA) + " kPa (" + report.message + ")";
      return false;
    }
    m_x = x;
    m_pressure = target;
    m_volume = m_model.volume(x);
    return true;
  }

  const Eigen::VectorXd& x() const { return m_x; }

  BulgeState state(bool keep_shape) const {
    BulgeState s;
    s.converged = true;
    s.message = "converged";
    if (keep_shape) s.deformed = unflatten(m_x);
    s.pressure_kpa = m_pressure / MPA_PER_KPA;
    s.volume_mm3 = m_volume;
    s.extension_ratio = std::sqrt(m_model.area(m_x) / m_model.rest_area());
    s.apex_height_mm = m_x[2];  // vertex 0 is the centre
    s.newton_iterations = m_iterations;
    return s;
  }

 private:
  static std::vector<bool> fixed_coordinates(int rings, int vertex_count) {
    std::vector<bool> fixed(static_cast<size_t>(3 * vertex_count), false);
    for (int v : bulge_disc_rim(rings))
      for (int a = 0; a < 3; ++a) fixed[static_cast<size_t>(3 * v + a)] = true;
    return fixed;
  }

  double cap_volume(double extension_ratio) const { return bulge_cap_volume(m_options.radius_mm, extension_ratio); }

  /// Lifts the flat disc vertically onto a spherical cap of volume `volume` and solves there.
  bool start(double volume, std::string& message) {
    const double a = m_options.radius_mm;
    // Cap height from its volume pi h (3 a^2 + h^2) / 6 by Newton (monotone in h).
    double h = 2 * volume / (PI * a * a);
    for (int i = 0; i < 50; ++i) {
      const double f = PI * h * (3 * a * a + h * h) / 6 - volume;
      h -= f / (PI * (a * a + h * h) / 2);
    }
    const double cap_radius = (a * a + h * h) / (2 * h);
    m_x = flat(m_rest.vertices);
    for (int v = 0; v < m_rest.vertex_count(); ++v) {
      const double r2 = m_x[3 * v] * m_x[3 * v] + m_x[3 * v + 1] * m_x[3 * v + 1];
      if (!m_fixed[static_cast<size_t>(3 * v)])
        m_x[3 * v + 2] = std::sqrt(std::max(0.0, cap_radius * cap_radius - r2)) - (cap_radius - h);
    }
    m_volume = m_model.volume(m_x);
    m_pressure = estimate_pressure(m_x);
    m_step = m_volume;
    m_started = true;
    NewtonReport report;
    if (volume_step(volume, report)) return true;
    message = "no equilibrium found on the first spherical-cap shape (" + report.message + ")";
    return false;
  }

  /// Least-squares pressure for a shape: the p minimising |grad W - p grad V| over the free coordinates.
  double estimate_pressure(const Eigen::VectorXd& x) const {
    const auto& assembly = m_solver.assembly();
    const Eigen::VectorXd g = assembly.restrict(m_model.elastic_gradient(x));
    const Eigen::VectorXd v = assembly.restrict(m_model.volume_gradient(x));
    const double vv = v.squaredNorm();
    return vv > 0 ? g.dot(v) / vv : 0.0;
  }

  bool volume_step(double target, NewtonReport& report) {
    // Predictor: scale heights; the cone volume is linear in the z column, so this hits the target exactly.
    Eigen::VectorXd x = m_x;
    if (m_volume > 0)
      for (int v = 0; v < m_rest.vertex_count(); ++v) x[3 * v + 2] *= target / m_volume;
    double pressure = m_pressure > 0 ? m_pressure : estimate_pressure(x);
    report = m_solver.solve_volume(x, pressure, target, m_settings);
    m_iterations += report.iterations;
    if (!report.converged) return false;
    m_x = x;
    m_pressure = pressure;
    m_volume = target;
    return true;
  }

  const BulgeTestOptions& m_options;
  TriMesh m_rest;
  fem::BalloonModel m_model;
  std::vector<bool> m_fixed;
  EquilibriumSolver m_solver;
  NewtonSettings m_settings;
  Eigen::VectorXd m_x;
  double m_pressure = 0.0;  // MPa
  double m_volume = 0.0;    // mm^3
  double m_step = 0.0;      // mm^3, last successful volume step
  bool m_started = false;
  int m_iterations = 0;
};

std::string options_problem(const BulgeTestOptions& options) {
  if (auto problem = material_problem(options.material); !problem.empty()) return problem;
  if (!(options.radius_mm > 0) || !std::isfinite(options.radius_mm)) return "disc radius must be positive (mm)";
  if (!(options.thickness_mm > 0) || !std::isfinite(options.thickness_mm)) return "disc thickness must be positive (mm)";
  if (options.rings < 2) return "the disc mesh needs at least 2 rings";
  return "";
}

BulgeState failed_state(const std::string& message) {
  BulgeState s;
  s.message = message;
  return s;
}

}  // namespace

TriMesh bulge_disc_mesh(double radius_mm, int rings) {
  if (rings < 1) throw std::invalid_argument("bulge_disc_mesh: rings must be >= 1");
  const int vertex_count = 1 + 3 * rings * (rings + 1);
  TriMesh mesh;
  mesh.vertices.resize(vertex_count, 3);
  mesh.vertices.row(0).setZero();
  auto ring_start = [](int k) { return k == 0 ? 0 : 1 + 3 * k * (k - 1); };
  for (int k = 1; k <= rings; ++k) {
    const double r = radius_mm * k / rings;
    for (int j = 0; j < 6 * k; ++j) {
      const double angle = 2 * PI * j / (6 * k);
      mesh.vertices.row(ring_start(k) + j) << r * std::cos(angle), r * std::sin(angle), 0.0;
    }
  }
  std::vector<std::array<int, 3>> faces;
  faces.reserve(static_cast<size_t>(6 * rings * rings));
  for (int k = 1; k <= rings; ++k) {
    // Zip ring k-1 (n_in vertices) with ring k (n_out), advancing along whichever ring's next vertex comes
    // first in angle: every triangle spans one edge of one ring and a vertex of the other.
    const int n_in = k == 1 ? 1 : 6 * (k - 1), n_out = 6 * k;
    const int s_in = ring_start(k - 1), s_out = ring_start(k);
    int i = 0, o = 0;
    while (i < (k == 1 ? 0 : n_in) || o < n_out) {
      const double next_in = k == 1 ? 1e9 : static_cast<double>(i + 1) / n_in;
      const double next_out = static_cast<double>(o + 1) / n_out;
      const int vi = s_in + (k == 1 ? 0 : i % n_in), vo = s_out + o % n_out;
      if (o < n_out && (next_out <= next_in || i >= n_in)) {
        faces.push_back({vi, vo, s_out + (o + 1) % n_out});
        ++o;
      } else {
        faces.push_back({vi, vo, s_in + (i + 1) % n_in});
        ++i;
      }
    }
  }
  mesh.faces.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f)
    mesh.faces.row(static_cast<int>(f)) << faces[f][0], faces[f][1], faces[f][2];
  return mesh;
}

std::vector<int> bulge_disc_rim(int rings) {
  std::vector<int> rim(static_cast<size_t>(6 * rings));
  for (int j = 0; j < 6 * rings; ++j) rim[static_cast<size_t>(j)] = 1 + 3 * rings * (rings - 1) + j;
  return rim;
}

double bulge_cap_volume(double radius_mm, double extension_ratio) {
  const double h = radius_mm * std::sqrt(std::max(0.0, extension_ratio * extension_ratio - 1.0));
  return PI * h * (3 * radius_mm * radius_mm + h * h) / 6;
}

BulgeState inflate_bulge_to_pressure(const BulgeTestOptions& options, double pressure_kpa) {
  BulgeCurve curve = bulge_pressure_sweep(options, {pressure_kpa}, true);
  if (curve.points.empty()) return failed_state(curve.message);
  return curve.points.back();
}

BulgeState inflate_bulge_to_volume(const BulgeTestOptions& options, double volume_mm3) {
  BulgeCurve curve = bulge_volume_sweep(options, {volume_mm3}, true);
  if (curve.points.empty()) return failed_state(curve.message);
  return curve.points.back();
}

BulgeCurve bulge_volume_sweep(const BulgeTestOptions& options, const std::vector<double>& volumes_mm3, bool keep_shapes) {
  BulgeCurve curve;
  const double start = now_s();
  if (auto problem = options_problem(options); !problem.empty()) {
    curve.message = problem;
    return curve;
  }
  BulgeRun run(options);
  curve.converged = true;
  double last = 0.0;
  for (double volume : volumes_mm3) {
    if (!(volume > last) || !std::isfinite(volume)) {
      curve.converged = false;
      curve.message = "volumes must be positive and increasing (mm^3)";
      break;
    }
    if (!run.advance_to_volume(volume, curve.message)) {
      curve.converged = false;
      break;
    }
    curve.points.push_back(run.state(keep_shapes));
    last = volume;
  }
  if (curve.converged) curve.message = "converged";
  curve.time_s = now_s() - start;
  return curve;
}

BulgeCurve bulge_pressure_sweep(const BulgeTestOptions& options, const std::vector<double>& pressures_kpa, bool keep_shapes) {
  BulgeCurve curve;
  const double start = now_s();
  if (auto problem = options_problem(options); !problem.empty()) {
    curve.message = problem;
    return curve;
  }
  BulgeRun run(options);
  curve.converged = true;
  double last = 0.0, peak = 0.0;
  for (double pressure_kpa : pressures_kpa) {
    const double target = pressure_kpa * MPA_PER_KPA;
    if (!(target > last) || !std::isfinite(target)) {
      curve.converged = false;
      curve.message = "pressures must be positive and increasing (kPa)";
      break;
    }
    bool reached = false;
    while (!reached) {
      const Eigen::VectorXd previous_x = run.started() ? run.x() : Eigen::VectorXd();
      const double previous_pressure = run.pressure_mpa();
      // Volume steps of about 20% keep the path well resolved; the run subdivides them when Newton fails.
      const double next_volume =
          run.started() ? 1.2 * run.volume() : bulge_cap_volume(options.radius_mm, FIRST_EXTENSION_RATIO);
      if (!run.advance_to_volume(next_volume, curve.message)) {
        curve.converged = false;
        break;
      }
      peak = std::max(peak, run.pressure_mpa());
      if (run.pressure_mpa() >= target) {
        if (previous_x.size() == 0) {
          // Bracketed on the first shape: bisect towards the flat disc is not possible; solve from here.
          if (!run.solve_at_pressure(run.x(), run.pressure_mpa() * 2, target, curve.message)) curve.converged = false;
        } else if (!run.solve_at_pressure(previous_x, previous_pressure, target, curve.message)) {
          curve.converged = false;
        }
        reached = curve.converged;
        if (!reached) break;
      } else if (run.pressure_mpa() < previous_pressure) {
        curve.converged = false;
        curve.message = "no equilibrium: " + std::to_string(pressure_kpa) +
                        " kPa exceeds the disc's maximum pressure of about " + std::to_string(peak / MPA_PER_KPA) +
                        " kPa (use volume control to pass it)";
        break;
      } else if (run.volume() > 1e4 * std::pow(options.radius_mm, 3)) {
        curve.converged = false;
        curve.message = "no equilibrium below a volume of 1e4 a^3";
        break;
      }
    }
    if (!curve.converged) break;
    curve.points.push_back(run.state(keep_shapes));
    last = target;
  }
  if (curve.converged) curve.message = "converged";
  curve.time_s = now_s() - start;
  return curve;
}

double BulgeResponse::pressure_at(double x) const {
  if (x <= 1.0) return 0.0;
  const auto it = std::lower_bound(extension_ratio.begin(), extension_ratio.end(), x);
  if (it == extension_ratio.end() || it == extension_ratio.begin()) return std::numeric_limits<double>::quiet_NaN();
  const size_t j = static_cast<size_t>(it - extension_ratio.begin());
  // Linear in u = (rho - 1)^(3/2): at small deflection rho - 1 ~ h^2 and p ~ h^3, so p is linear in u there
  // (plain linear interpolation from the flat disc overestimates early pressures by several percent).
  auto u = [](double rho) { return std::pow(rho - 1.0, 1.5); };
  const double t = (u(x) - u(extension_ratio[j - 1])) / (u(extension_ratio[j]) - u(extension_ratio[j - 1]));
  return pressure_kpa[j - 1] + t * (pressure_kpa[j] - pressure_kpa[j - 1]);
}

BulgeResponse fem_bulge_response(const Material& material, double radius_mm, double thickness_mm,
                                 double max_extension_ratio, int rings, const CancelToken* cancel) {
  BulgeResponse response;
  response.extension_ratio = {1.0};
  response.pressure_kpa = {0.0};
  BulgeTestOptions options;
  options.material = material;
  options.radius_mm = radius_mm;
  options.thickness_mm = thickness_mm;
  options.rings = rings;
  options.residual_tolerance = 1e-7;
  if (!options_problem(options).empty()) return response;
  BulgeRun run(options);
  std::string message;
  double rho_guess = FIRST_EXTENSION_RATIO;
  for (int k = 0; k < 300 && response.extension_ratio.back() < max_extension_ratio; ++k) {
    if (cancel != nullptr && cancel->cancelled()) break;
    const double volume =
        std::max(bulge_cap_volume(radius_mm, rho_guess), run.started() ? 1.0001 * run.volume() : 0.0);
    if (!run.advance_to_volume(volume, message)) break;
    const BulgeState s = run.state(false);
    if (!(s.extension_ratio > response.extension_ratio.back())) break;  // the disc no longer grows in area
    response.extension_ratio.push_back(s.extension_ratio);
    response.pressure_kpa.push_back(s.pressure_kpa);
    // Small steps near the flat disc, where p grows like (rho - 1)^(3/2); 0.02 (or 2%) further on.
    rho_guess = s.extension_ratio + std::clamp(0.5 * (s.extension_ratio - 1.0), 0.002, 0.02) +
                std::max(0.0, 0.02 * (s.extension_ratio - 2.0));
  }
  return response;
}

std::vector<double> fem_bulge_pressures(const Material& material, const MeasurementSet& set, int rings) {
  std::vector<double> result(set.x.size(), std::numeric_limits<double>::quiet_NaN());
  if (set.x.empty()) return result;
  const double x_max = *std::max_element(set.x.begin(), set.x.end());
  const BulgeResponse response = fem_bulge_response(material, set.disc_radius_mm, set.thickness_mm, x_max, rings);
  for (size_t i = 0; i < set.x.size(); ++i) result[i] = response.pressure_at(set.x[i]);
  return result;
}

BulgeModel fem_bulge_model(int rings) {
  return [rings](const Material& material, const MeasurementSet& set) { return fem_bulge_pressures(material, set, rings); };
}

}  // namespace balloon
