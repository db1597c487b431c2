#pragma once
/// The size a simulate or design request may ask its mesh to be scaled to (`size_mm`: the bounding-box
/// diagonal, mm), checked the same way for both.
#include <string>

namespace balloon::jobs {

/// A balloon a kilometre across is surely a unit mistake; the bound also keeps scaled coordinates finite.
inline constexpr double MAX_SIZE_MM = 1e6;

/// Empty when `size_mm` is usable (0 keeps the mesh's size), else why not.
std::string size_mm_problem(double size_mm);

/// Empty when a mesh `diagonal_mm` across (bounding-box diagonal, after any size_mm) is no larger than
/// MAX_SIZE_MM, else why not, with the remedy. A mesh read as mm from a file in micrometres or a CAD unit
/// was simulated at 1e30 mm ("converged", at 3.8e-28 kPa).
std::string mesh_size_problem(double diagonal_mm);

}  // namespace balloon::jobs
