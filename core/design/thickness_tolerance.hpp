#pragma once
/// Fabrication tolerance of a design (paper sec. 6): how far the inflated shape moves when the
/// membrane thickness varies randomly per element, as it does on a dipped or brushed mold.
#include <vector>

#include "mesh/tri_mesh.hpp"
#include "solve/inflation.hpp"

namespace balloon {

/// Deviation for one perturbation level.
struct ThicknessToleranceLevel {
  double perturbation = 0.0;        ///< relative amplitude a: each element's thickness is h * (1 + U(-a, a))
  double mean_deviation_mm = 0.0;   ///< mean over samples of the mean vertex distance to the nominal shape (mm)
  double max_deviation_mm = 0.0;    ///< largest single-vertex distance seen over all samples (mm)
  int samples = 0;                  ///< samples that converged (and so entered the means)
  int failed_samples = 0;           ///< samples whose inflation did not converge (left out of the means)
};

/// The 10% and 20% levels, in that order.
struct ThicknessTolerance {
  std::vector<ThicknessToleranceLevel> levels;
};

/// Inflates `rest` (closed, outward mesh, mm) `samples` times for each of the perturbation levels 10% and
/// 20%, each time with per-element thickness h_e = h_nominal * (1 + U(-a, a)) drawn from a fixed-seed
/// generator (same seed, same numbers), and measures the mean vertex distance (mm) to
/// `nominal_inflated` (#V by 3, mm) after rigidly aligning the perturbed shape onto it.
/// Control: volume control at the nominal volume ratio V(nominal_inflated) / V(rest), warm-started from
/// the nominal shape, so every sample holds the same air and the difference is shape alone (pressure
/// control near a pressure maximum may jump to another branch). Material, nominal thickness
/// (thickness_mm or element_thickness_mm) and fixed vertices come from `nominal_options`.
/// Cost: 2 * samples warm-started inflations.
ThicknessTolerance thickness_tolerance(const TriMesh& rest, const InflationOptions& nominal_options,
                                       const Positions& nominal_inflated, int samples, unsigned seed);

}  // namespace balloon
