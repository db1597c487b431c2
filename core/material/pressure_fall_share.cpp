#include "material/pressure_fall_share.hpp"

#include <cmath>

#include "mesh/mesh_geometry.hpp"

namespace balloon {

double area_share_in_pressure_fall(const TriMesh& rest, const Positions& inflated, const PressureFallBand& band) {
  double total = 0.0, in_band = 0.0;
  for (int f = 0; f < rest.face_count(); ++f) {
    const Eigen::Vector3i face = rest.faces.row(f);
    const double rest_area = triangle_area(rest.vertices, face);
    const double area = triangle_area(inflated, face);
    total += area;
    if (rest_area > 0.0 && band.contains(std::sqrt(area / rest_area))) in_band += area;
  }
  return total > 0.0 ? in_band / total : 0.0;
}

}  // namespace balloon
