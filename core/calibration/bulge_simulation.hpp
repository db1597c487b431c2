#pragma once
/// FEM simulation of the bulge test (paper sec. 4): a flat disc of radius a clamped at its rim and inflated
/// by pressure from below. The disc is meshed here, simulated with the membrane model of core/fem and the
/// Newton solver of core/solve, and swept in enclosed volume so the curve passes pressure maxima.
#include <string>
#include <vector>

#include "material/fitting.hpp"
#include "material/material.hpp"
#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// A flat disc of radius `radius_mm` (mm) in the plane z = 0, centred at the origin, triangulated by
/// `rings` concentric rings (ring k has 6k vertices at radius k a / rings; vertex 0 is the centre), so
/// triangles are near-equilateral and the rim vertices lie exactly on the circle. #V = 1 + 3 rings (rings+1).
/// Triangles are counter-clockwise seen from +z (normal +z: inflation moves the disc towards +z).
TriMesh bulge_disc_mesh(double radius_mm, int rings);

/// Indices of the rim vertices of bulge_disc_mesh(radius, rings) (the last ring, 6 rings vertices).
std::vector<int> bulge_disc_rim(int rings);

/// Geometry, material and resolution of a bulge test.
struct BulgeTestOptions {
  Material material;
  double radius_mm = 10.0;            ///< radius a of the clamped opening (mm)
  double thickness_mm = 1.0;          ///< rest thickness H of the disc (mm)
  int rings = 12;                     ///< mesh resolution, see bulge_disc_mesh(); >= 2
  double residual_tolerance = 1e-8;   ///< relative Newton tolerance (see NewtonSettings)
  int max_newton_iterations = 60;     ///< per solve
};

/// One equilibrium state of the inflated disc.
struct BulgeState {
  bool converged = false;
  std::string message;            ///< "converged" or why not
  Positions deformed;             ///< #V by 3 equilibrium positions (mm)
  double pressure_kpa = 0.0;      ///< pressure below the disc (kPa)
  double volume_mm3 = 0.0;        ///< volume between the disc and the plane z = 0 (mm^3)
  double extension_ratio = 1.0;   ///< mean extension ratio sqrt(A / A0) (dimensionless)
  double apex_height_mm = 0.0;    ///< height of the centre vertex above the rim plane (mm)
  int newton_iterations = 0;
};

/// A pressure-extension curve, points in increasing volume.
struct BulgeCurve {
  bool converged = false;          ///< every requested point was reached
  std::string message;             ///< "converged" or where the sweep stopped
  std::vector<BulgeState> points;  ///< states reached (positions kept only when keep_shapes)
  double time_s = 0.0;
};

/// Inflates the disc to pressure `pressure_kpa` (> 0) by following the volume path up from the flat disc
/// and solving at the exact pressure once it is bracketed. Fails (converged = false, message) above the
/// disc's pressure maximum: use volume control to pass it.
BulgeState inflate_bulge_to_pressure(const BulgeTestOptions& options, double pressure_kpa);

/// Inflates the disc to enclosed volume `volume_mm3` (> 0) with the pressure as an unknown (passes maxima).
BulgeState inflate_bulge_to_volume(const BulgeTestOptions& options, double volume_mm3);

/// Volume-controlled sweep through `volumes_mm3` (increasing, > 0); stops at the first failure.
/// `keep_shapes` = false drops the positions of the states to save memory.
BulgeCurve bulge_volume_sweep(const BulgeTestOptions& options, const std::vector<double>& volumes_mm3,
                              bool keep_shapes = false);

/// Pressure sweep through `pressures_kpa` (increasing, > 0), following the volume path between them;
/// stops (converged = false) at the first pressure above the disc's pressure maximum.
BulgeCurve bulge_pressure_sweep(const BulgeTestOptions& options, const std::vector<double>& pressures_kpa,
                                bool keep_shapes = false);

/// Volume of a spherical cap over the disc with mean extension ratio `extension_ratio` (mm^3): the cap of
/// height h = a sqrt(rho^2 - 1) has volume pi h (3 a^2 + h^2) / 6. Used to size volume sweeps.
double bulge_cap_volume(double radius_mm, double extension_ratio);

/// A pressure-extension curve of the FEM bulge test: increasing extension ratios (from 1) and pressures.
struct BulgeResponse {
  std::vector<double> extension_ratio;  ///< #points, strictly increasing, first = 1 (flat disc)
  std::vector<double> pressure_kpa;     ///< #points (kPa), first = 0
  /// Linear interpolation at `extension_ratio`: 0 at or below 1, NaN beyond the last point.
  double pressure_at(double extension_ratio) const;
};

/// Volume-controlled sweep from the flat disc in steps of about 0.02 in extension ratio (estimated from the
/// spherical cap) until `max_extension_ratio` is passed, the sweep fails or `cancel` (may be null) fires.
BulgeResponse fem_bulge_response(const Material& material, double radius_mm, double thickness_mm,
                                 double max_extension_ratio, int rings = 6, const CancelToken* cancel = nullptr);

/// Pressures (kPa) of the FEM bulge test at each extension ratio of `set` (a Bulge set), interpolated
/// linearly in a volume-controlled sweep that runs past the largest measured ratio; NaN where the sweep
/// cannot reach a ratio. `rings` sets the mesh resolution (coarse keeps fits fast).
std::vector<double> fem_bulge_pressures(const Material& material, const MeasurementSet& set, int rings = 6);

/// fem_bulge_pressures as a FitOptions::bulge_model. Exact but slow inside fit_material (one FEM sweep per
/// model evaluation: about a minute for a Hart-Smith fit of 10 points); see fit_material_with_fem_bulge.
BulgeModel fem_bulge_model(int rings = 6);

}  // namespace balloon
