#pragma once
/// Test oracle for the bulge test: the axisymmetric equilibrium of a thin incompressible membrane disc of
/// radius a clamped at its rim, solved by shooting from the pole (independent of core/fem and core/solve).
#include "material/material.hpp"

namespace balloon::testing {

/// An axisymmetric equilibrium of the clamped disc.
struct AxisymmetricBulge {
  bool ok = false;
  double pressure_kpa = 0.0;     ///< pressure (kPa)
  double pole_stretch = 1.0;     ///< equibiaxial stretch at the pole (dimensionless)
  double apex_height_mm = 0.0;   ///< height of the pole above the rim plane (mm)
  double extension_ratio = 1.0;  ///< sqrt(A / A0) (dimensionless)
  double rim_hoop_stretch = 1.0; ///< r(a) / a, 1 when the rim condition holds
};

/// Integrates the membrane equations (reference radius R, meridional stretch l1, hoop stretch l2 = r / R,
/// meridian angle phi) from the pole with pole stretch `pole_stretch` at pressure `pressure_kpa`:
///   d(H R W_1)/dR = H W_2 cos(phi)           (meridional equilibrium)
///   phi' = l1 (p - T2 sin(phi) / r) / T1      (normal equilibrium, T1 = H W_1 / l2, T2 = H W_2 / l1)
///   r' = l1 cos(phi), z' = -l1 sin(phi)
/// with RK4 on `steps` steps. rim_hoop_stretch of the result says how far the rim lands from r = a.
AxisymmetricBulge integrate_axisymmetric_bulge(const Material& material, double radius_mm, double thickness_mm,
                                               double pole_stretch, double pressure_kpa, int steps = 1000);

/// For a pole stretch, the pressure at which the rim lands at r = a (bisection on the pressure).
AxisymmetricBulge shoot_axisymmetric_bulge(const Material& material, double radius_mm, double thickness_mm,
                                           double pole_stretch);

/// The clamped equilibrium whose apex height is `apex_height_mm` (bisection on the pole stretch).
AxisymmetricBulge axisymmetric_bulge_at_apex_height(const Material& material, double radius_mm, double thickness_mm,
                                                    double apex_height_mm);

/// The clamped equilibrium whose mean extension ratio is `extension_ratio`.
AxisymmetricBulge axisymmetric_bulge_at_extension_ratio(const Material& material, double radius_mm,
                                                        double thickness_mm, double extension_ratio);

}  // namespace balloon::testing
