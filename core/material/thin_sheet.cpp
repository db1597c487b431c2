#include "material/thin_sheet.hpp"

#include <cmath>
#include <sstream>

namespace balloon {

std::string thickness_problem(double thickness_mm) {
  if (std::isfinite(thickness_mm) && thickness_mm >= MIN_THICKNESS_MM) return "";
  std::ostringstream out;
  out << "thickness must be a positive number of mm, at least " << MIN_THICKNESS_MM << " (a micrometre), got "
      << thickness_mm;
  return out.str();
}

bool within_thin_sheet_limit(double thickness_mm, double size_mm) {
  return !(thickness_mm > MAX_THICKNESS_PER_DIAGONAL * size_mm * (1.0 + THIN_SHEET_SLACK));
}

std::string thin_sheet_problem(double thickness_mm, double rest_diagonal_mm) {
  // 10% is the model's rule of thumb, not a sharp edge, so it has 2% slack: a design target is checked at
  // the size the user gave, and its remeshed surface, which lies inside the given one, is a little smaller
  // (a 10 mm target at 1,500 vertices: 4.99 mm at the start instead of 5). Without the slack, a design at
  // the limit passed at submit and was refused by the job as `start_failed`.
  if (within_thin_sheet_limit(thickness_mm, rest_diagonal_mm)) return "";
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
