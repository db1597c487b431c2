#include "jobs/mesh_size.hpp"

#include <cmath>
#include <cstdio>

namespace balloon::jobs {

std::string size_mm_problem(double size_mm) {
  if (std::isfinite(size_mm) && size_mm >= 0.0 && size_mm <= MAX_SIZE_MM) return "";
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), "size must be a number of mm up to %g (or 0 to keep the mesh's size), got %.6g",
                MAX_SIZE_MM, size_mm);
  return buffer;
}

std::string mesh_size_problem(double diagonal_mm) {
  if (diagonal_mm <= MAX_SIZE_MM) return "";
  char buffer[240];
  std::snprintf(buffer, sizeof(buffer),
                "the mesh is %.3g mm across (bounding-box diagonal), more than %g mm (a kilometre): mesh coordinates "
                "are read as mm; scale it (--size MM)",
                diagonal_mm, MAX_SIZE_MM);
  return buffer;
}

}  // namespace balloon::jobs
