#pragma once
/// Numbers as the solver's messages show them: three significant digits (the curve's four), or as many
/// as it takes to tell a value from the target it fell short of; pressures in kPa.
#include <string>

namespace balloon {

constexpr double MPA_PER_KPA = 1e-3;

/// `value` to `digits` significant digits, as printf's %g writes it ("7.3", "1.2e+03").
std::string format_number(double value, int digits = 3);
/// A value short of `target`, with enough digits to show it (4.99996 short of 5 rather than "5").
std::string format_number_short_of(double value, double target);
/// A pressure given in MPa, written in kPa to four significant digits ("23.13 kPa").
std::string format_kpa(double mpa);

}  // namespace balloon
