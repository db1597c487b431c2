#pragma once
/// Fits a rubber law (Neo-Hookean, Mooney-Rivlin, Hart-Smith) to one or several measurement sets jointly
/// by nonlinear least squares (Levenberg-Marquardt), with the parameters kept physical, and reports
/// residuals, standard errors and whether the fitted curve reproduces the data's regimes (paper sec. 4).
#include <functional>
#include <string>
#include <vector>

#include "material/material.hpp"
#include "material/measurements.hpp"
#include "progress.hpp"
#include "result.hpp"

namespace balloon {

/// Model pressures (kPa) of a bulge set at each of its points (#set.x), for `material` on a disc of radius
/// set.disc_radius_mm and thickness set.thickness_mm: at the extension ratios set.x, or at the apex heights
/// set.apex_height_mm where the set carries them (they do only at the measured points; set.y is zeroed).
/// Entries may be NaN where the model cannot reach a point (they then count as a large residual).
using BulgeModel = std::function<std::vector<double>(const Material& material, const MeasurementSet& set)>;

/// Bulge-test model in the thin-membrane spherical-cap approximation (no FEM). Assumptions: the disc of
/// radius a inflates to a spherical cap of height h and radius Rc = (a^2 + h^2) / (2 h); its area is
/// A = pi (a^2 + h^2), so the mean extension ratio rho = sqrt(A / A0) gives h = a sqrt(rho^2 - 1); the
/// cap is taken as uniformly equibiaxially stretched with stretch l = rho, so at the pole the wall is
/// H / l^2 thick and carries the Cauchy stress l P_ET(l); Laplace's law at the pole then gives
///   p = 2 H P_ET(l) / (l Rc)              (MPa; returned in kPa)
/// which reduces to the thin-sphere law when Rc = l R. This is an approximation: a clamped disc is not
/// uniformly stretched (planar tension at the rim, larger stretch at the pole); at small strain it gives
/// p = 12 mu H t^3 / a (t = h / a), whose coefficient differs from the exact small-deflection membrane
/// solution (Hencky) by very roughly 10-20%, so fitted moduli carry an error of that order. Apex heights
/// in the set are not used (the cap ties them to rho). The exact axisymmetric membrane of
/// core/calibration/axisymmetric_bulge replaces this model through FitOptions::bulge_model (the fit job
/// always does).
std::vector<double> spherical_cap_bulge_pressures(const Material& material, const MeasurementSet& set);

/// Options of fit_material(). Defaults suit stress tables and the spherical-cap bulge model.
struct FitOptions {
  /// Forward model of bulge sets; empty = spherical_cap_bulge_pressures (an approximation, see there).
  BulgeModel bulge_model;
  /// Residuals are relative: r = (y_model - y_data) / max(|y_data|, floor), floor = this fraction of the
  /// set's largest |y|, so points near zero stress neither dominate nor divide by zero. Default 0.01.
  double relative_floor = 0.01;
  /// Levenberg-Marquardt runs started from the best points of a coarse parameter grid. Default 4.
  int starts = 4;
  /// Cap on residual evaluations per Levenberg-Marquardt run. Default 2000.
  int max_evaluations = 2000;
  /// Points of the fine grid on which the fitted curve is evaluated for the regime report. Default 200.
  int regime_grid_points = 200;
  /// Checked between residual evaluations (and FEM sweep steps); once it fires the fit stops and fails
  /// with FIT_CANCELLED. May be null.
  const CancelToken* cancel = nullptr;
};

/// The error of a fit stopped by its cancel token.
inline constexpr const char* FIT_CANCELLED = "cancelled";

/// Regimes of a curve y(x) sampled at increasing x (paper sec. 4.2). Slopes are least-squares slopes in
/// windows a quarter of the x range wide, at 13 window positions spanning the range; with s_first, s_last
/// the first and last window slopes, s_min the smallest, and tol = 5% of the largest |slope|:
///  - inflection: the slope decreases then increases (the second derivative changes sign from - to +):
///    s_min is at an interior window and both s_first and s_last exceed it by more than tol;
///  - stiffening: at the end of the range the curve rises and its slope has grown: s_last > 0 and
///    s_last exceeds s_min by more than tol.
struct Regimes {
  bool inflection = false;
  bool stiffening = false;
};
/// The regimes of y(x); x strictly increasing, #x = #y >= 2 (fewer points: no regimes).
Regimes detect_regimes(const std::vector<double>& x, const std::vector<double>& y);

/// The curve whose regimes are reported for a set: pressure (kPa) against extension ratio for bulge
/// sets, the equivalent balloon curve P_ET(l) / l^2 (MPa) for equibiaxial tables, P(l) (MPa) otherwise.
std::vector<double> regime_curve(const MeasurementSet& set);

/// Model values y (MPa or kPa, as set.y) at the abscissae `x` (#x) for the geometry and kind of `set`.
/// A bulge model sees the set's apex heights only when `x` is the set's own x.
std::vector<double> model_values(const Material& material, const MeasurementSet& set, const std::vector<double>& x,
                                 const FitOptions& options = {});

/// Fit quality on one measurement set.
struct SetFit {
  std::string label;
  TestKind kind = TestKind::Uniaxial;
  int points = 0;
  int dropped_compression_points = 0;  ///< stress tables: rows with stretch < 1 the parser left out (MeasurementSet)
  double rms_residual = 0, max_residual = 0;  ///< |y_model - y_data| in residual_unit
  std::string residual_unit;                  ///< "MPa" (nominal stress) or "kPa" (bulge pressure)
  double rms_relative_residual = 0, max_relative_residual = 0;  ///< the fitted relative residuals
  Regimes data_regimes, model_regimes;  ///< of regime_curve() of the data / of the model on a fine grid
};

/// Result of a fit. Residuals over all points of all sets.
struct FitResult {
  Material material;                 ///< fitted law; params in parameter_names() order (MPa; k1, k2 none)
  int points = 0;                    ///< data points used
  double rms_residual = 0;           ///< RMS of |y_model - y_data| in residual_unit
  double max_residual = 0;           ///< largest |y_model - y_data| in residual_unit
  std::string residual_unit;         ///< "MPa", "kPa", or "mixed" when stress tables and bulge data are fitted jointly
  double rms_relative_residual = 0;  ///< RMS of the minimized relative residuals (dimensionless)
  double max_relative_residual = 0;  ///< largest |relative residual|
  /// One standard error per parameter (parameter units): sqrt of diag(s^2 (J^T J)^-1), J the Jacobian of
  /// the relative residuals w.r.t. the parameters, s^2 = sum r^2 / (points - #params). Infinite for a
  /// parameter the data cannot identify; empty when points == #params. A linearisation: rough at a
  /// bound (k1, k2 or C2 = 0).
  std::vector<double> std_errors;
  /// Regimes of the headline set (the first bulge set, else the first equibiaxial set, else the first set).
  bool data_inflection = false, data_stiffening = false;
  bool model_inflection = false, model_stiffening = false;
  std::vector<SetFit> sets;  ///< per input set, same order
  bool converged = false;    ///< Levenberg-Marquardt met its tolerances (else the best point found)
  int evaluations = 0;       ///< residual-vector evaluations over all starts
  std::string message;       ///< solver status and notes (e.g. a parameter at its bound)
};

/// Fits `model` to all points of `sets` jointly. Moduli are optimized as logarithms (mu, C1, G > 0), the
/// other constants as squares (C2, k1, k2 >= 0). Fails with a message for unusable data (see
/// measurement_problem()) or fewer points than parameters; non-convergence is reported in the result.
Result<FitResult> fit_material(MaterialModel model, const std::vector<MeasurementSet>& sets, const FitOptions& options = {});

}  // namespace balloon
