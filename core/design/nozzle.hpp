#pragma once
/// The inflation nozzle: `--nozzle X,Y,Z[,RADIUS]` or `--nozzle auto`, and the rest-shape vertices it
/// holds in place (paper section 5.2, "Nozzle Attachment").
#include <Eigen/Core>
#include <string>
#include <vector>

#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// A parsed nozzle request.
struct NozzleSpec {
  bool automatic = false;                        ///< "auto": at the lowest vertex along z
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< requested centre (mm); unused when automatic
  double radius_mm = 0.0;                        ///< 0: the default, DEFAULT_NOZZLE_RADIUS_FRACTION * bbox diagonal
};

/// Default nozzle radius as a fraction of the mesh's bounding-box diagonal.
inline constexpr double DEFAULT_NOZZLE_RADIUS_FRACTION = 0.05;

/// Parses "auto" (any case) or "X,Y,Z" or "X,Y,Z,RADIUS" (mm, spaces allowed around numbers).
/// Fails with a message naming the problem on anything else, a non-finite number or a radius <= 0.
Result<NozzleSpec> parse_nozzle(const std::string& text);

/// The vertices a nozzle holds.
struct NozzleSelection {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< position of the closest vertex (mm)
  int center_vertex = -1;                        ///< the vertex closest to the requested centre
  double radius_mm = 0.0;                        ///< radius used (mm)
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  ///< outward unit normal averaged over the selection
  std::vector<int> vertices;                     ///< held vertices, sorted ascending
};

/// Selects the vertices of `rest` (closed mesh, mm) within the radius of the nozzle centre that are
/// connected to the closest vertex through such vertices (so a nearby but separate part of the
/// surface is not caught), always including the closest vertex and its one-ring. "auto" picks the
/// vertex with the smallest z (lowest index on ties). Fails if the requested centre is farther from the
/// surface's nearest vertex than max(radius, 10% of the bbox diagonal): most likely a typo or wrong units.
Result<NozzleSelection> select_nozzle(const TriMesh& rest, const NozzleSpec& spec);

}  // namespace balloon
