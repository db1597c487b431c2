#pragma once

#include <string>

namespace balloon {

/// The membrane (and hinge) model is a thin sheet's: its stresses are the mid-surface's, constant through
/// the thickness. A sheet thicker than this fraction of its balloon's bounding-box diagonal is refused
/// rather than simulated as if thin. A sphere's box diagonal is 3.5 radii, so the limit is a radius of at
/// least 2.9 thicknesses; issue 10's smallest balloons (10 mm, 0.5 mm) sit at half of it.
constexpr double MAX_THICKNESS_PER_DIAGONAL = 0.1;
/// Relative slack on that limit (see thin_sheet_problem): a sheet up to 10.2% passes.
constexpr double THIN_SHEET_SLACK = 0.02;

/// Whether a sheet `thickness_mm` thick on a rest shape `size_mm` across is within the thin-sheet limit
/// (MAX_THICKNESS_PER_DIAGONAL, with THIN_SHEET_SLACK): the one rule for balloons and bulge discs.
bool within_thin_sheet_limit(double thickness_mm, double size_mm);

/// Why a sheet `thickness_mm` thick on a rest shape `rest_diagonal_mm` across (bounding-box diagonal) is
/// not a thin sheet, naming both sizes and the remedy; "" when it is one.
std::string thin_sheet_problem(double thickness_mm, double rest_diagonal_mm);

/// The thinnest sheet simulated (mm): a micrometre, far below any rubber sheet. Far below it the forces
/// vanish in rounding (at 1e-300 mm every shape "balanced" at zero pressure: converged in 0 Newton steps).
constexpr double MIN_THICKNESS_MM = 1e-3;

/// Why `thickness_mm` is no sheet thickness (not a finite number of at least MIN_THICKNESS_MM), or "".
std::string thickness_problem(double thickness_mm);

}  // namespace balloon
