#pragma once
/// The whole pressure-volume curve of a balloon in one run: equilibria at points spaced geometrically
/// over a range of volume ratios (volume control, passes pressure maxima) or of pressures, followed as one
/// continuation path (each point starts from the previous equilibrium), with the pressure's local maxima
/// and minima along the path (where a balloon under pressure snaps).
#include <optional>
#include <string>
#include <vector>

#include "material/material.hpp"
#include "mesh/tri_mesh.hpp"
#include "progress.hpp"
#include "solve/inflation.hpp"

namespace balloon {

inline constexpr int MIN_CURVE_POINTS = 2;
inline constexpr int MAX_CURVE_POINTS = 1000;
/// Largest volume ratio or pressure (kPa) a curve may ask for: past it no rubber membrane holds.
inline constexpr double MAX_CURVE_VOLUME_RATIO = 1e6;
inline constexpr double MAX_CURVE_PRESSURE_KPA = 1e6;

struct PressureVolumeCurveOptions {
  Material material;
  double thickness_mm = 0.5;  ///< rest membrane thickness h (mm), uniform
  /// VolumeRatio: `from`..`to` are V / V_rest (1 < from < to); Pressure: pressures in kPa (0 < from < to).
  InflationControl control = InflationControl::VolumeRatio;
  double from = 0.0;
  double to = 0.0;
  int points = 0;                     ///< MIN_CURVE_POINTS..MAX_CURVE_POINTS, spaced geometrically
  double residual_tolerance = 1e-8;   ///< as InflationOptions::residual_tolerance
  double max_time_s = 0.0;            ///< wall-time budget of the whole path (s); 0 means none
  ProgressCallback progress;          ///< optional: one event per point (phase "curve", iteration = point index)
  const CancelToken* cancel = nullptr;
};

/// One equilibrium of the curve. Values never computed (the point was not reached) are empty.
struct CurvePoint {
  double target = 0.0;      ///< requested V / V_rest, or pressure (kPa)
  bool converged = false;   ///< an equilibrium at the target within the inflation's residual test
  std::optional<double> volume_ratio;  ///< V / V_rest
  std::optional<double> pressure_kpa;  ///< kPa
  std::optional<double> mean_stretch;  ///< sqrt(A / A_rest)
  std::optional<double> max_stretch;   ///< largest principal stretch over all triangles
  /// Negative eigen-directions of the stiffness at the equilibrium (0 = stable): under volume control
  /// of the volume-bordered KKT matrix (the constraint's own direction not counted), under pressure
  /// control of Hess(W - p V). Empty when not converged or not determinable (singular stiffness).
  std::optional<int> unstable_modes;
  std::string message;      ///< "converged", or why not
};

/// A local extremum of the pressure along the path: at a converged point whose converged neighbours
/// both have lower (maximum) or higher (minimum) pressure, or, under pressure control, one the volume
/// path passed between two points (InflationResult::passed_extrema).
struct CurveExtremum {
  bool maximum = true;       ///< a pressure maximum (the balloon snaps past it under pressure); else a minimum
  /// Index of the sampled extreme point; for an extremum that pressure control passed between two points
  /// (the path's pressures at the points only rise), the index of the point after it.
  int point = 0;
  /// The extremum estimated by the parabola through that point and its two neighbours, in log(V / V_rest)
  /// (exact for a quadratic pressure; within a fraction of the point spacing otherwise); for a passed one,
  /// through the volume path's states around it.
  double volume_ratio = 0.0;
  double pressure_kpa = 0.0;
};

struct PressureVolumeCurve {
  bool converged = false;  ///< every point converged
  /// Why the path ended: Converged when it reached the last point; otherwise the stop of the first point
  /// that did not converge (the path ends there, see trace_pressure_volume_curve).
  InflationStop stop = InflationStop::NoEquilibrium;
  std::string message;             ///< "converged", or where and why the path stopped
  std::vector<CurvePoint> points;  ///< one per requested point, in path order
  std::vector<CurveExtremum> extrema;  ///< in path order
  Positions last_shape;            ///< #V by 3: the last converged equilibrium (mm); the rest shape if none
  int last_converged_point = -1;   ///< index into points; -1 when none converged
  double rest_volume_mm3 = 0.0;
  int newton_iterations = 0;       ///< totals over the path
  int factorizations = 0;
  int load_steps = 0;
  double time_s = 0.0;             ///< wall time of the whole path (s)
  /// The sheet's bending stiffness was on at the path's end (InflationResult::bending: once switched on
  /// where the membrane alone had no stable state, it stays on for the rest of the path).
  bool bending = false;
  int flipped_cap_slivers = 0;     ///< InflationResult::flipped_cap_slivers of the path's mesh
};

/// The targets of a curve: `points` values from `from` to `to`, in geometric progression (equal ratios).
std::vector<double> curve_targets(double from, double to, int points);

/// Empty when the range and the point count are usable, else the problem as a sentence (checks only the
/// control, from, to and points; the material and thickness are checked by the path).
std::string curve_range_problem(InflationControl control, double from, double to, int points);

/// Follows one continuation path through every target. A point without an equilibrium ends the path
/// (continuation needs the previous equilibrium; pressure control past a pressure maximum has none):
/// that point says why, and the points after it are not converged and have no values
/// ("not reached: ..."). Never throws for bad input: that is stop == InvalidInput with every point empty.
PressureVolumeCurve trace_pressure_volume_curve(const TriMesh& rest, const PressureVolumeCurveOptions& options);

/// The local pressure extrema of `points` (see CurveExtremum).
std::vector<CurveExtremum> pressure_extrema(const std::vector<CurvePoint>& points);

}  // namespace balloon
