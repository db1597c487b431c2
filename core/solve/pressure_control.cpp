// InflationRun's pressure control (inflation_run.hpp): the volume path followed until its pressure
// reaches the target, then the equilibrium at that pressure, or the answer that it lies above the
// balloon's pressure maximum.
#include "solve/inflation_run.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "solve/parabola_vertex.hpp"
#include "solve/pressure_bracket.hpp"
#include "solve/quantity_text.hpp"

namespace balloon {
namespace {

/// Pressure control past a pressure maximum below the target follows the volume path this far (V / V_rest,
/// issue 14's widest curve) for the pressure to climb back before it calls the target above the maximum.
constexpr double MAX_VOLUME_RATIO_PAST_A_PEAK = 250.0;
/// Volume-controlled solves that close the bracket around a target pressure at most (settle_at_pressure).
constexpr int MAX_BRACKET_STEPS = 40;

/// Where a path stopped by its time limit (or a cancel) got to: "time limit reached at 1.2 kPa (volume
/// ratio 1.8), on the way to 3 kPa". The result holds that equilibrium.
std::string stopped_on_the_way(const std::string& reason, const PathPoint& reached, double rest_volume,
                               double target_pressure) {
  return reason + " at " + format_kpa(reached.pressure) + " (volume ratio " + format_number(reached.volume / rest_volume) +
         "), on the way to " + format_kpa(target_pressure);
}

}  // namespace

bool InflationRun::inflate_to_pressure(PathPoint& state, double target_pressure, std::string& message) {
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
  m_passed_extrema.clear();
  std::optional<PathPoint> before_previous;  // the path's state before `previous`, once there is one
  while (state.pressure < target_pressure) {
    PathPoint previous = state;
    if (!volume_step(state, state.volume + step, report)) {
      if (report.stop != NewtonStop::Cancelled && stopped_passing_through_itself(state, message)) {
        if (snapped_from)
          message += "; before that " + fall_after(*snapped_from) + ", below the " + format_kpa(target_pressure) + " asked for";
        return false;
      }
      if (stopped(report)) {
        message = stopped_on_the_way(report.message, state, m_rest_volume, target_pressure);
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
    if (before_previous) note_pressure_turn(*before_previous, previous, state);
    before_previous = previous;
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

void InflationRun::note_pressure_turn(const PathPoint& before, const PathPoint& previous, const PathPoint& after) {
  const bool maximum = previous.pressure > before.pressure && previous.pressure > after.pressure;
  const bool minimum = previous.pressure < before.pressure && previous.pressure < after.pressure;
  if (!maximum && !minimum) return;
  const double log_ratio[3] = {std::log(before.volume / m_rest_volume), std::log(previous.volume / m_rest_volume),
                               std::log(after.volume / m_rest_volume)};
  const double pressure_kpa[3] = {before.pressure / MPA_PER_KPA, previous.pressure / MPA_PER_KPA,
                                  after.pressure / MPA_PER_KPA};
  double vertex_log_ratio = log_ratio[1], vertex_pressure_kpa = pressure_kpa[1];
  if (log_ratio[0] < log_ratio[1] && log_ratio[1] < log_ratio[2])
    parabola_vertex(log_ratio, pressure_kpa, &vertex_log_ratio, &vertex_pressure_kpa);
  m_passed_extrema.push_back({maximum, std::exp(vertex_log_ratio), vertex_pressure_kpa});
}

std::string InflationRun::fall_after(const PathPoint& peak) const {
  // The highest maximum the path noted is that peak, placed between the path's steps as the curve's
  // extrema are, so that a report names one maximum, not two.
  double pressure_mpa = peak.pressure, volume_ratio = peak.volume / m_rest_volume;
  for (const PassedExtremum& turn : m_passed_extrema)
    if (turn.maximum && turn.pressure_kpa * MPA_PER_KPA >= pressure_mpa)
      pressure_mpa = turn.pressure_kpa * MPA_PER_KPA, volume_ratio = turn.volume_ratio;
  return "the pressure fell after a maximum of " + format_kpa(pressure_mpa) + " at volume ratio " +
         format_number(volume_ratio);
}

bool InflationRun::above_maximum_pressure(PathPoint& state, const PathPoint& peak, double target_pressure, std::string& message) {
  m_stop = InflationStop::AboveMaximumPressure;
  message = "no equilibrium: " + format_kpa(target_pressure) + " exceeds the balloon's maximum pressure of about " +
            format_kpa(peak.pressure) + " (the highest on its volume path up to volume ratio " +
            format_number(state.volume / m_rest_volume) + "; use volume control to pass it)";
  state = peak;
  return false;
}

bool InflationRun::settle_at_pressure(PathPoint& state, PathPoint low, PathPoint high, double target_pressure, std::string& message) {
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
        state = closer;
        message = stopped_on_the_way(report.message, state, m_rest_volume, target_pressure);
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

bool InflationRun::settle_by_pressure_newton(PathPoint& state, const PathPoint& closer, double target_pressure,
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
    message = stopped_on_the_way(at_pressure.message, closer, m_rest_volume, target_pressure);
  } else {
    message = "no equilibrium found at " + format_kpa(target_pressure) + " (" + failed.message +
              (failed.residual_norm > 0.0 ? ", residual " + format_number(failed.residual_norm) + " N" : "") +
              "; then at that pressure: " + at_pressure.message + ")";
  }
  state = closer;
  return false;
}

}  // namespace balloon
