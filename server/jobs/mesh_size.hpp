#pragma once
/// The size a simulate or design request may ask its mesh to be scaled to (`size_mm`: the bounding-box
/// diagonal, mm), checked the same way for both.
#include <string>

namespace balloon::jobs {

/// A balloon a kilometre across is surely a unit mistake; the bound also keeps scaled coordinates finite.
inline constexpr double MAX_SIZE_MM = 1e6;

/// Empty when `size_mm` is usable (0 keeps the mesh's size), else why not.
std::string size_mm_problem(double size_mm);

}  // namespace balloon::jobs
