#pragma once
/// The bulge test as an axisymmetric membrane (paper sec. 4): a flat disc of radius a and rest thickness H,
/// clamped at its rim and inflated by pressure, solved as a 1D problem along the meridian. This is the
/// exact thin-membrane model of the test (no spherical-cap approximation) at the cost of one ODE per
/// state, so material fits can call it hundreds of times; the 3D FEM disc of bulge_simulation is its
/// validation reference (tests/core/calibration/test_axisymmetric_bulge.cpp).
///
/// Equations (reference radius R in [0, a], meridional stretch l1, hoop stretch l2 = r / R, meridian angle
/// phi from the horizontal, W(l1, l2) = Psi(I1, I2) of the incompressible law with W_i = dW/dl_i):
///   d(R W_1)/dR = W_2 cos(phi)                                   (meridional equilibrium)
///   dphi/dR = (l1 l2 p a / H - W_2 sin(phi) / R) / W_1  (R in units of a; normal equilibrium)
///   dr/dR = l1 cos(phi),  dz/dR = -l1 sin(phi)
/// integrated from the pole (equibiaxial stretch l0, curvature from Laplace's law) to the rim by RK4; the
/// pressure of a pole stretch is the one that lands the rim on r = a (l2(a) = 1). In these variables the
/// response scales exactly: p is proportional to H / a and to the leading modulus, heights to a.
#include <string>
#include <vector>

#include "material/fitting.hpp"
#include "material/material.hpp"
#include "material/measurements.hpp"

namespace balloon {

/// Resolution and limits of the axisymmetric solution. Defaults keep pressures within 2e-4 of a 1000-step
/// solution, and curve interpolation within 5e-4 of the states it passes between (measured in the tests).
struct AxisymmetricBulgeOptions {
  int steps = 48;                  ///< RK4 steps from pole to rim (graded towards the pole); >= 8
  double pole_stretch_step = 0.08; ///< curve spacing in sqrt(l0 - 1) (dimensionless); > 0
  double max_pole_stretch = 20.0;  ///< a curve stops here (dimensionless)
  int max_points = 400;            ///< a curve stops after this many states
};

/// One axisymmetric equilibrium of the clamped disc.
struct AxisymmetricBulgeState {
  bool converged = false;        ///< the rim condition |r(a)/a - 1| <= 1e-10 held
  double pole_stretch = 1.0;     ///< equibiaxial stretch at the pole (dimensionless)
  double pressure_kpa = 0.0;     ///< pressure (kPa)
  double apex_height_mm = 0.0;   ///< height of the pole above the rim plane (mm)
  double extension_ratio = 1.0;  ///< mean extension ratio sqrt(A / A0) (dimensionless)
  double volume_mm3 = 0.0;       ///< volume between the membrane and the rim plane (mm^3)
};

/// The equilibrium with pole stretch `pole_stretch` (> 1) of a disc of radius `radius_mm` (mm, > 0) and
/// rest thickness `thickness_mm` (mm, > 0). converged = false when no pressure lands the rim on r = a.
AxisymmetricBulgeState axisymmetric_bulge_at_pole_stretch(const Material& material, double radius_mm,
                                                          double thickness_mm, double pole_stretch,
                                                          const AxisymmetricBulgeOptions& options = {});

/// A sequence of inflations from the flat disc, in increasing pole stretch (so it passes pressure maxima).
struct AxisymmetricBulgeCurve {
  bool converged = false;                    ///< reached the requested extent
  std::string message;                       ///< "converged" or where and why the curve stopped
  std::vector<AxisymmetricBulgeState> points;  ///< first = flat disc (all zero, stretch 1)
  /// Pressure (kPa) at extension ratio `extension_ratio` by cubic interpolation along the curve: 0 at or
  /// below 1, NaN beyond the last point.
  double pressure_at_extension_ratio(double extension_ratio) const;
  /// Pressure (kPa) at apex height `apex_height_mm` (mm): 0 at or below 0, NaN beyond the last point.
  double pressure_at_apex_height(double apex_height_mm) const;
};

/// Inflates the disc until the extension ratio reaches `max_extension_ratio` and the apex height reaches
/// `max_apex_height_mm` (mm), or a limit of `options` stops it (converged = false, message).
AxisymmetricBulgeCurve axisymmetric_bulge_curve(const Material& material, double radius_mm, double thickness_mm,
                                                double max_extension_ratio, double max_apex_height_mm = 0.0,
                                                const AxisymmetricBulgeOptions& options = {});

/// Pressures (kPa) of a bulge set (#set.x): at its apex heights when the set has them (the measured shape
/// coordinate, free of the cap assumption that often turns heights into extension ratios), else at its
/// extension ratios. NaN where the curve cannot reach a point. A FitOptions::bulge_model.
std::vector<double> axisymmetric_bulge_pressures(const Material& material, const MeasurementSet& set,
                                                 const AxisymmetricBulgeOptions& options = {});

/// axisymmetric_bulge_pressures as a FitOptions::bulge_model that remembers the last few dimensionless
/// curves: the response is linear in the leading modulus (mu, C1 at fixed C2 / C1, G), so the fit's
/// steps along it reuse a curve. One model per fit (a mutex guards the cache, so sharing is safe but serial).
BulgeModel axisymmetric_bulge_model(const AxisymmetricBulgeOptions& options = {});

}  // namespace balloon
