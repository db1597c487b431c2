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

}  // namespace balloon::jobs
