#pragma once
/// The volumes at which pressure control looks for its target between two points of the volume path: a
/// bracket [low, high] whose pressures lie on either side of the target, narrowed by regula falsi with the
/// Illinois rule (inflation.cpp's settle_at_pressure solves at each volume it names).
///
/// Near the stress-free rest the pressure is a power of the added volume, p ~ (V - V_rest)^k: k = 1 for
/// a curved sheet, k = 3 for a flat face, which must stretch to bulge at all. Interpolated linearly from
/// the rest state, a target far below the path's first pressure named a volume far too small on a flat
/// face (a rounded box, Mooney-Rivlin, 0.01 kPa: ratio 1.002 against about 1.08), where the nearly slack
/// sheet's solves crept to the iteration limit. So the bracket interpolates log p against
/// log (V - V_rest), which a power law makes a straight line; from the rest state itself (no pressure, no
/// logarithm) with the exponent of the last two high ends, or a flat face's 3 before there are two.
/// Away from the rest both interpolants name nearly the same volume.

namespace balloon {

/// A converged point of the volume path: its enclosed volume (mm^3) and pressure (MPa).
struct BracketEnd {
  double volume = 0.0;
  double pressure = 0.0;
};

class PressureBracket {
 public:
  /// `low.pressure` <= `target_pressure` <= `high.pressure`, `low.volume` < `high.volume`.
  PressureBracket(double rest_volume, double target_pressure, BracketEnd low, BracketEnd high);

  /// The volume to solve at next, strictly inside the bracket.
  double next_volume() const;
  /// Replaces the end on the same side of the target as `reached` (an equilibrium at next_volume()).
  /// Returns true if that was the low end.
  bool narrow(BracketEnd reached);

  const BracketEnd& low() const { return m_low; }
  const BracketEnd& high() const { return m_high; }

 private:
  double linear_volume() const;
  /// NaN where the power law does not apply (an end at or below the rest volume, or without pressure
  /// above the rest).
  double power_law_volume() const;

  double m_rest_volume;
  double m_target;
  BracketEnd m_low, m_high;
  BracketEnd m_replaced_high{};    ///< the high end before the latest one (volume 0: none yet)
  double m_low_weight = 1.0;       ///< Illinois: an end kept twice running has its excess weighed down
  double m_high_weight = 1.0;
  int m_kept_side = 0;             ///< 1: the high end was kept last time (low replaced); -1: the low end
};

}  // namespace balloon
