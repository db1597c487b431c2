#include "solve/pressure_bracket.hpp"

#include <algorithm>
#include <cmath>

namespace balloon {
namespace {

/// p ~ (V - V_rest)^3 near the rest: a flat face has to stretch before it bulges.
constexpr double FLAT_FACE_EXPONENT = 3.0;
/// Exponents measured from two high ends are kept within these (past a pressure maximum the pressure
/// falls with the volume; the fraction then comes from the bracket's other end as well).
constexpr double MIN_EXPONENT = 0.5;
constexpr double MAX_EXPONENT = 4.0;
/// The next volume stays this fraction of the bracket away from its ends: a solve at an end is wasted.
constexpr double END_MARGIN = 1e-3;

}  // namespace

PressureBracket::PressureBracket(double rest_volume, double target_pressure, BracketEnd low, BracketEnd high)
    : m_rest_volume(rest_volume), m_target(target_pressure), m_low(low), m_high(high) {}

double PressureBracket::linear_volume() const {
  const double low_excess = m_low_weight * (m_low.pressure - m_target);
  const double high_excess = m_high_weight * (m_high.pressure - m_target);
  const double fraction = -low_excess / (high_excess - low_excess);
  return m_low.volume + fraction * (m_high.volume - m_low.volume);
}

double PressureBracket::power_law_volume() const {
  const double low_added = m_low.volume - m_rest_volume, high_added = m_high.volume - m_rest_volume;
  if (!(low_added >= 0.0 && high_added > low_added && m_high.pressure > 0.0 && m_target > 0.0 &&
        m_low.pressure >= 0.0))
    return std::nan("");
  const double high_excess = m_high_weight * std::log(m_high.pressure / m_target);
  const double log_high = std::log(high_added);
  double log_added;
  if (m_low.pressure > 0.0 && low_added > 0.0) {
    const double low_excess = m_low_weight * std::log(m_low.pressure / m_target);
    const double log_low = std::log(low_added);
    log_added = log_low + (log_high - log_low) * -low_excess / (high_excess - low_excess);
  } else {
    // From the stress-free rest: along the power law through the high end.
    double exponent = FLAT_FACE_EXPONENT;
    const double replaced_added = m_replaced_high.volume - m_rest_volume;
    if (m_replaced_high.pressure > m_high.pressure && replaced_added > high_added) {
      exponent = std::clamp(std::log(m_replaced_high.pressure / m_high.pressure) / std::log(replaced_added / high_added),
                            MIN_EXPONENT, MAX_EXPONENT);
    }
    log_added = log_high - high_excess / exponent;
  }
  return m_rest_volume + std::exp(log_added);
}

double PressureBracket::next_volume() const {
  double volume = power_law_volume();
  if (!std::isfinite(volume)) volume = linear_volume();
  const double span = m_high.volume - m_low.volume;
  if (!std::isfinite(volume)) volume = m_low.volume + 0.5 * span;
  return std::clamp(volume, m_low.volume + END_MARGIN * span, m_high.volume - END_MARGIN * span);
}

bool PressureBracket::narrow(BracketEnd reached) {
  if (reached.pressure < m_target) {
    m_low = reached;
    m_low_weight = 1.0;
    if (m_kept_side == 1) m_high_weight *= 0.5;
    m_kept_side = 1;
    return true;
  }
  m_replaced_high = m_high;
  m_high = reached;
  m_high_weight = 1.0;
  if (m_kept_side == -1) m_low_weight *= 0.5;
  m_kept_side = -1;
  return false;
}

}  // namespace balloon
