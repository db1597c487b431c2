#include "solve/quantity_text.hpp"

#include <sstream>

namespace balloon {

std::string format_number(double value, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << value;
  return out.str();
}

std::string format_number_short_of(double value, double target) {
  for (int digits = 3; digits < 9; ++digits) {
    std::ostringstream out, goal;
    out.precision(digits);
    goal.precision(digits);
    out << value;
    goal << target;
    if (out.str() != goal.str()) return out.str();
  }
  return format_number(value);
}

std::string format_kpa(double mpa) {
  std::ostringstream out;
  out.precision(4);
  out << mpa / MPA_PER_KPA << " kPa";
  return out.str();
}

}  // namespace balloon
