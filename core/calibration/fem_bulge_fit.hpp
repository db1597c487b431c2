#pragma once
/// Material fitting against the FEM bulge test (paper sec. 4): bulge sets are simulated by the clamped disc
/// of calibration/bulge_simulation rather than approximated by a spherical cap.
#include <vector>

#include "material/fitting.hpp"
#include "material/material.hpp"
#include "result.hpp"

namespace balloon {

/// Superseded: the fit job now fits bulge sets with the exact axisymmetric membrane inside the least squares
/// (calibration/axisymmetric_bulge), about ten times faster and without the valley drift described below.
/// Kept as the "before" of tests/bench/bench_fitting and as a fit against the 3D FEM disc itself.
///
/// fit_material() with bulge sets simulated by the FEM disc, made fast by a corrected spherical cap: the
/// bulge model inside the least squares is spherical_cap_bulge_pressures(m) * c(rho), where the correction
/// c = p_FEM / p_cap is computed by one FEM sweep at the current fit; refit, recompute c at the new fit, and
/// repeat until the model the fit used agrees with the FEM at the fitted material within 0.5% of the largest
/// measured pressure (at most `max_rounds` refits; the message says which). The reported residuals are
/// then FEM residuals. The search neglects how c depends on the material, so along a flat valley of the
/// cost (G against k2 for Hart-Smith) it can stop at a point a little off the FEM least-squares optimum.
/// Sets of other kinds are fitted as by fit_material. `options.bulge_model` is ignored; `options.cancel`
/// is checked between rounds and sweep steps (the fit then fails with FIT_CANCELLED).
Result<FitResult> fit_material_with_fem_bulge(MaterialModel model, const std::vector<MeasurementSet>& sets,
                                              const FitOptions& options = {}, int rings = 16, int max_rounds = 10);

}  // namespace balloon
