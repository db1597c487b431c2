#include "solve/pressure_volume_curve.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "solve/inflation_run.hpp"
#include "solve/parabola_vertex.hpp"
#include "solve/quantity_text.hpp"

namespace balloon {
namespace {

/// Significant digits of the numbers in the curve's messages (its ranges are typed to more than three).
constexpr int CURVE_DIGITS = 4;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string describe_target(InflationControl control, double target) {
  return control == InflationControl::Pressure ? format_number(target, CURVE_DIGITS) + " kPa"
                                               : "volume ratio " + format_number(target, CURVE_DIGITS);
}

}  // namespace

std::vector<double> curve_targets(double from, double to, int points) {
  std::vector<double> targets(static_cast<size_t>(std::max(points, 0)));
  const double log_ratio = std::log(to / from);
  for (int i = 0; i < points; ++i)
    targets[static_cast<size_t>(i)] = points == 1 ? from : from * std::exp(log_ratio * i / (points - 1));
  if (points >= 2) targets.back() = to;  // exactly the end the user asked for
  return targets;
}

std::string curve_range_problem(InflationControl control, double from, double to, int points) {
  if (points < MIN_CURVE_POINTS || points > MAX_CURVE_POINTS)
    return "points must be between " + std::to_string(MIN_CURVE_POINTS) + " and " + std::to_string(MAX_CURVE_POINTS) +
           ", got " + std::to_string(points);
  if (!std::isfinite(from) || !std::isfinite(to)) return "the range must be two finite numbers";
  if (control == InflationControl::VolumeRatio) {
    if (!(from > 1.0))
      return "the volume-ratio range must start above 1 (the rest volume), got " + format_number(from, CURVE_DIGITS);
    if (!(to <= MAX_CURVE_VOLUME_RATIO))
      return "the volume-ratio range must end at most at " + format_number(MAX_CURVE_VOLUME_RATIO, CURVE_DIGITS);
  } else {
    if (!(from > 0.0)) return "the pressure range must start above 0 kPa, got " + format_number(from, CURVE_DIGITS);
    if (!(to <= MAX_CURVE_PRESSURE_KPA))
      return "the pressure range must end at most at " + format_number(MAX_CURVE_PRESSURE_KPA, CURVE_DIGITS) + " kPa";
  }
  if (!(from < to))
    return "the range must be A:B with A < B, got " + format_number(from, CURVE_DIGITS) + ":" +
           format_number(to, CURVE_DIGITS);
  return "";
}

std::vector<CurveExtremum> pressure_extrema(const std::vector<CurvePoint>& points) {
  std::vector<CurveExtremum> extrema;
  for (size_t i = 1; i + 1 < points.size(); ++i) {
    const CurvePoint& before = points[i - 1];
    const CurvePoint& here = points[i];
    const CurvePoint& after = points[i + 1];
    if (!before.converged || !here.converged || !after.converged) continue;
    const double p[3] = {*before.pressure_kpa, *here.pressure_kpa, *after.pressure_kpa};
    const bool maximum = p[1] > p[0] && p[1] >= p[2];
    const bool minimum = p[1] < p[0] && p[1] <= p[2];
    if (!maximum && !minimum) continue;
    CurveExtremum extremum;
    extremum.maximum = maximum;
    extremum.point = static_cast<int>(i);
    const double x[3] = {std::log(*before.volume_ratio), std::log(*here.volume_ratio), std::log(*after.volume_ratio)};
    double log_ratio = x[1], pressure = p[1];
    if (x[0] < x[1] && x[1] < x[2]) parabola_vertex(x, p, &log_ratio, &pressure);
    extremum.volume_ratio = std::exp(log_ratio);
    extremum.pressure_kpa = pressure;
    extrema.push_back(extremum);
  }
  return extrema;
}

namespace {

/// The curve's points, none reached yet.
PressureVolumeCurve unreached_points(const TriMesh& rest, const std::vector<double>& targets) {
  PressureVolumeCurve curve;
  curve.last_shape = rest.vertices;
  for (double target : targets) {
    CurvePoint point;
    point.target = target;
    curve.points.push_back(point);
  }
  return curve;
}

/// Follows one continuation path through `curve`'s points (unreached_points), filling each it reaches,
/// up to the first without an equilibrium or whose equilibrium passes through itself. Returns whether it
/// ended at a membrane equilibrium (the sheet's bending off) that passes through itself.
bool follow_path(const TriMesh& rest, const PressureVolumeCurveOptions& options, const InflationOptions& inflation,
                 double start, PressureVolumeCurve& curve) {
  // Per-point progress below; the path's own load steps would flood the watchers with meshes.
  InflationPath path(rest, inflation);
  std::string stopped;  // set once the path has ended: why the remaining points were not reached
  bool membrane_touched = false;
  std::vector<CurveExtremum> passed;  // pressure control: extrema the path passed between points
  for (size_t i = 0; i < curve.points.size(); ++i) {
    CurvePoint& point = curve.points[i];
    if (!stopped.empty()) {
      point.message = "not reached: " + stopped;
      continue;
    }
    const InflationResult result = path.advance(options.control, point.target);
    for (const PassedExtremum& turn : result.passed_extrema)
      passed.push_back({turn.maximum, static_cast<int>(i), turn.volume_ratio, turn.pressure_kpa});
    curve.rest_volume_mm3 = result.rest_volume_mm3;
    curve.newton_iterations = result.newton_iterations;
    curve.factorizations = result.factorizations;
    curve.load_steps = result.load_steps;
    curve.bending = result.bending;
    curve.flipped_cap_slivers = result.flipped_cap_slivers;
    if (!result.converged) {
      point.message = result.message;
      curve.stop = result.stop;
      curve.message = "the path stopped at " + describe_target(options.control, point.target) + ": " + result.message;
      stopped = "the path stopped at " + describe_target(options.control, point.target);
      continue;
    }
    // As a single inflation ends where its walls pass through each other (inflate()), so does the curve:
    // past that, this model (no contact) follows no balloon. (The latex knot at 200 mm over 1.05:27 went
    // on through three such points and called them converged.)
    if (passes_through_itself(rest, result.deformed)) {
      membrane_touched = !result.bending;
      point.message = "no equilibrium: the " + std::string(result.bending ? "bent sheet's" : "membrane's") +
                      " equilibrium at volume ratio " + format_number(result.volume_ratio, CURVE_DIGITS) + " (" +
                      format_number(result.pressure_kpa, CURVE_DIGITS) +
                      " kPa) passes through itself; its walls touch there, and this model has no contact";
      curve.stop = InflationStop::PassesThroughItself;
      curve.message = "the path stopped at " + describe_target(options.control, point.target) + ": " + point.message;
      stopped = "the path stopped at " + describe_target(options.control, point.target);
      continue;
    }
    point.converged = true;
    point.message = result.message;  // "converged", or with what it passed (a snap under pressure control)
    point.volume_ratio = result.volume_ratio;
    point.pressure_kpa = result.pressure_kpa;
    point.mean_stretch = result.mean_stretch;
    point.max_stretch = result.max_stretch;
    const int modes =
        options.control == InflationControl::Pressure ? path.pressure_unstable_modes() : result.unstable_modes;
    if (modes >= 0) point.unstable_modes = modes;
    curve.last_shape = result.deformed;
    curve.last_converged_point = static_cast<int>(i);
    if (options.progress) {
      ProgressEvent event;
      event.phase = "curve";
      event.iteration = static_cast<int>(i);
      event.elapsed_s = now_s() - start;
      event.residual_norm = result.residual_norm;
      event.pressure_kpa = result.pressure_kpa;
      event.shape = &curve.last_shape;
      options.progress(event);
    }
  }
  if (stopped.empty() && !curve.points.empty()) {
    curve.converged = true;
    curve.stop = InflationStop::Converged;
    curve.message = "converged";
  }
  curve.extrema = pressure_extrema(curve.points);
  curve.extrema.insert(curve.extrema.end(), passed.begin(), passed.end());
  return membrane_touched;
}

}  // namespace

PressureVolumeCurve trace_pressure_volume_curve(const TriMesh& rest, const PressureVolumeCurveOptions& options) {
  const double start = now_s();
  const std::string range_problem = curve_range_problem(options.control, options.from, options.to, options.points);
  if (!range_problem.empty()) {
    PressureVolumeCurve curve = unreached_points(rest, {});
    curve.stop = InflationStop::InvalidInput;
    curve.message = range_problem;
    curve.time_s = now_s() - start;
    return curve;
  }
  const std::vector<double> targets = curve_targets(options.from, options.to, options.points);
  InflationOptions inflation;
  inflation.material = options.material;
  inflation.thickness_mm = options.thickness_mm;
  inflation.residual_tolerance = options.residual_tolerance;
  inflation.max_time_s = options.max_time_s;
  inflation.cancel = options.cancel;
  PressureVolumeCurve curve = unreached_points(rest, targets);
  const bool membrane_touched = follow_path(rest, options, inflation, start, curve);
  const double spent_s = now_s() - start;
  const bool time_left = !(options.max_time_s > 0.0) || spent_s < options.max_time_s;
  if (membrane_touched && time_left && !(options.cancel && options.cancel->cancelled())) {
    // As inflate() does: the real sheet's bending can keep the walls apart where the membrane's touch (latex
    // spot at 100 mm, 1 kPa: its slack membrane crumpled through itself at x1.05; bent, it inflates). The
    // whole path again with it on, so that every point is the same model's.
    inflation.bending = BendingUse::On;
    if (options.max_time_s > 0.0) inflation.max_time_s = options.max_time_s - spent_s;
    PressureVolumeCurve bent = unreached_points(rest, targets);
    follow_path(rest, options, inflation, start, bent);
    const int newton_iterations = curve.newton_iterations + bent.newton_iterations;
    const int factorizations = curve.factorizations + bent.factorizations;
    const int load_steps = curve.load_steps + bent.load_steps;
    if (bent.last_converged_point >= curve.last_converged_point)
      curve = std::move(bent);
    else
      curve.message += "; tried again with the sheet's bending: " + bent.message;
    curve.newton_iterations = newton_iterations;  // both passes' work
    curve.factorizations = factorizations;
    curve.load_steps = load_steps;
  }
  curve.time_s = now_s() - start;
  return curve;
}

}  // namespace balloon
