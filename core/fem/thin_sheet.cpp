#include "fem/thin_sheet.hpp"

#include <cmath>
#include <sstream>

namespace balloon {

std::string thin_sheet_problem(double thickness_mm, double rest_diagonal_mm) {
  // A hair of slack, so a balloon exactly at the limit is not refused for rounding.
  if (!(thickness_mm > MAX_THICKNESS_PER_DIAGONAL * rest_diagonal_mm * (1.0 + 1e-9))) return "";
  std::ostringstream out;
  out.precision(3);
  const double percent = 100.0 * (thickness_mm / rest_diagonal_mm);
  out << "the sheet (" << thickness_mm << " mm) is ";
  if (std::isfinite(percent))
    out << percent << "% of";
  else
    out << "far thicker than";
  out << " the uninflated balloon's size (bounding-box diagonal " << rest_diagonal_mm
      << " mm); the thin-sheet model needs at most " << 100.0 * MAX_THICKNESS_PER_DIAGONAL
      << "%. Mesh coordinates are read as mm: scale the mesh up (--size MM) or give a thinner --thickness";
  return out.str();
}

}  // namespace balloon
