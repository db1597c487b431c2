#include "material/measurements.hpp"

#include "material/thin_sheet.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <string_view>
#include <utility>

namespace balloon {
namespace {

// A drop of the stress below an earlier row larger than this fraction of the table's stress range is
// treated as a broken table rather than digitising noise (the published tables drop by < 1%).
constexpr double STRESS_DROP_TOLERANCE = 0.10;

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

/// A cell as messages quote it: cut to 40 characters, control bytes as '?', so that an error stays one short line.
std::string quoted_cell(const std::string& cell) {
  std::string shown = cell.substr(0, 40);
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return "'" + shown + (cell.size() > 40 ? "...'" : "'");
}

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

bool is_stress_table(TestKind kind) { return kind != TestKind::Bulge; }

/// Bounds on measured values (see validate): the largest stress (MPa) or pressure (kPa) a table may have.
constexpr double MIN_LARGEST_STRESS_MPA = 1e-7;
constexpr double MAX_STRESS_MPA = 1e5;
constexpr double MIN_LARGEST_PRESSURE_KPA = 1e-6;
constexpr double MAX_PRESSURE_KPA = 1e6;
/// A bulge disc no larger than any mesh may be (mm).
constexpr double MAX_DISC_RADIUS_MM = 1e6;
/// The largest stretch (or bulge extension ratio) a table may hold: rubbers break below about 10.
constexpr double MAX_MEASURED_STRETCH = 20.0;

/// Why a stretch far beyond any rubber's break is in the data, with the likely mix-up; "" below the bound.
std::string stretch_beyond_rubber(const std::string& x_name, double x) {
  if (!(x > MAX_MEASURED_STRETCH)) return "";
  return x_name + " " + number_text(x) + " is beyond any rubber (rubbers break below a stretch of about 10; at most " +
         number_text(MAX_MEASURED_STRETCH) + " is accepted): is the column the elongation in percent? The " +
         x_name + " is a length ratio (100% elongation is a stretch of 2)";
}

/// The hint for tables whose rows all had stretch < 1: often the strain, not the stretch.
std::string dropped_compression_text(int dropped) {
  return std::to_string(dropped) + (dropped == 1 ? " row" : " rows") +
         " with stretch below 1 dropped: compression is not fitted; if the column holds the strain dL/L0, give the "
         "stretch 1 + strain";
}

std::string expected_header(TestKind kind) {
  return is_stress_table(kind) ? "stretch,nominal_stress_MPa" : "pressure_kpa,extension_ratio[,apex_height_mm]";
}

/// Checks the rules documented at parse_measurements; `where(i)` names row i ("line 7" or "point 3").
std::string validate(const MeasurementSet& set, const std::function<std::string(size_t)>& where) {
  const size_t n = set.x.size();
  if (set.y.size() != n) return "the data has " + std::to_string(n) + " x values but " + std::to_string(set.y.size()) + " y values";
  if (!set.apex_height_mm.empty() && set.apex_height_mm.size() != n)
    return "the data has " + std::to_string(n) + " points but " + std::to_string(set.apex_height_mm.size()) + " apex heights";
  const std::string x_name = is_stress_table(set.kind) ? "stretch" : "extension ratio";
  const std::string y_name = is_stress_table(set.kind) ? "nominal stress" : "pressure";
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(set.x[i]) || !std::isfinite(set.y[i])) return where(i) + ": values must be finite numbers";
    if (auto beyond = stretch_beyond_rubber(x_name, set.x[i]); !beyond.empty()) return where(i) + ": " + beyond;
    if (is_stress_table(set.kind)) {
      if (set.x[i] < 1.0) return where(i) + ": stretch " + number_text(set.x[i]) + " < 1 (compression is not fitted)";
      if (set.y[i] < 0.0)
        return where(i) + ": negative nominal stress " + number_text(set.y[i]) + " MPa at stretch " + number_text(set.x[i]) +
               " >= 1 (tension)";
    } else {
      if (set.y[i] < 0.0) return where(i) + ": negative pressure " + number_text(set.y[i]) + " kPa";
      if (set.x[i] < 1.0)
        return where(i) + ": extension ratio " + number_text(set.x[i]) + " < 1 (an inflated disc only grows in area)";
      if (!set.apex_height_mm.empty() && !(set.apex_height_mm[i] >= 0.0 && std::isfinite(set.apex_height_mm[i])))
        return where(i) + ": apex height must be a finite number >= 0 mm";
    }
    if (i > 0 && !(set.x[i] > set.x[i - 1]))
      return where(i) + ": " + x_name + " " + number_text(set.x[i]) + " is not larger than the previous row's " +
             number_text(set.x[i - 1]) + " (rows must be in loading order, " + x_name + " strictly increasing)";
  }
  if (n < 2) {
    const std::string dropped =
        set.dropped_compression_points > 0 ? "; " + dropped_compression_text(set.dropped_compression_points) : "";
    return (n == 0 ? "no data rows" : "only 1 data point (at least 2 are needed to fit a curve)") + dropped;
  }
  // The data's scale against what a rubber can give: a modulus of 1 Pa to 100 GPa (material.hpp). Far
  // outside it no fit exists, and the optimizer only said "no starting point reproduces the data's sign".
  const double largest = *std::max_element(set.y.begin(), set.y.end());
  const auto [smallest_y, largest_y] = is_stress_table(set.kind) ? std::pair{MIN_LARGEST_STRESS_MPA, MAX_STRESS_MPA}
                                                                 : std::pair{MIN_LARGEST_PRESSURE_KPA, MAX_PRESSURE_KPA};
  // (All zeros is a problem of its own, which the fit names.)
  if (largest > 0.0 && !(largest >= smallest_y && largest <= largest_y)) {
    std::ostringstream out;
    out << "the largest " << y_name << ", " << number_text(largest) << (is_stress_table(set.kind) ? " MPa" : " kPa")
        << ", is outside what a rubber gives (" << smallest_y << " to " << largest_y
        << (is_stress_table(set.kind) ? " MPa): are the units MPa?" : " kPa): are the units kPa?");
    return out.str();
  }
  if (is_stress_table(set.kind)) {
    const auto [lo, hi] = std::minmax_element(set.y.begin(), set.y.end());
    const double range = *hi - *lo;
    double running_max = set.y[0];
    for (size_t i = 1; i < n; ++i) {
      if (set.y[i] < running_max - STRESS_DROP_TOLERANCE * range)
        return where(i) + ": nominal stress " + number_text(set.y[i]) + " MPa falls far below an earlier row's " +
               number_text(running_max) + " MPa although the stretch grew (stress must rise with stretch)";
      running_max = std::max(running_max, set.y[i]);
    }
  } else {
    if (!(set.y.back() > set.y.front()))
      return "pressure " + number_text(set.y.back()) + " kPa at the largest extension ratio is not above the pressure " +
             number_text(set.y.front()) + " kPa at the smallest: the extension ratio must grow with pressure overall";
  }
  return "";
}

}  // namespace

std::string test_kind_name(TestKind kind) {
  switch (kind) {
    case TestKind::Bulge: return "bulge";
    case TestKind::Uniaxial: return "uniaxial";
    case TestKind::Equibiaxial: return "equibiaxial";
    case TestKind::PureShear: return "pure-shear";
  }
  return "unknown";
}

Result<TestKind> parse_test_kind(const std::string& name) {
  for (auto kind : {TestKind::Bulge, TestKind::Uniaxial, TestKind::Equibiaxial, TestKind::PureShear})
    if (lower(trim(name)) == test_kind_name(kind)) return kind;
  return fail("unknown test '" + name + "' (known: bulge, uniaxial, equibiaxial, pure-shear)");
}

Result<MeasurementSet> parse_measurements(const std::string& csv_text, TestKind kind, const std::string& label) {
  MeasurementSet set;
  set.kind = kind;
  set.label = label;
  if (csv_text.find_first_not_of(" \t\r\n") == std::string::npos) return fail("no data: the text is empty");

  // Column roles: 0 = x, 1 = y, 2 = apex height.
  const bool stress = is_stress_table(kind);
  const std::vector<std::string> names = stress ? std::vector<std::string>{"stretch", "nominal_stress_mpa"}
                                                : std::vector<std::string>{"extension_ratio", "pressure_kpa", "apex_height_mm"};
  std::vector<int> role_of_column;
  std::vector<int> line_of_row;
  std::istringstream stream(csv_text);
  // A UTF-8 byte order mark (spreadsheets write one with "CSV UTF-8") is not part of the first column's name.
  constexpr std::string_view BYTE_ORDER_MARK = "\xEF\xBB\xBF";
  if (csv_text.rfind(BYTE_ORDER_MARK, 0) == 0) stream.ignore(static_cast<std::streamsize>(BYTE_ORDER_MARK.size()));
  std::string raw;
  int line_number = 0;
  bool have_header = false;
  while (std::getline(stream, raw)) {
    ++line_number;
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    const auto cells = split_cells(line);
    const std::string at_line = "line " + std::to_string(line_number);
    if (!have_header) {
      have_header = true;
      std::vector<bool> seen(names.size(), false);
      // A header of the other family is the likely mistake of passing the wrong --test: say so.
      std::string hint;
      if (stress && lower(line).find("pressure_kpa") != std::string::npos) hint = "; this looks like bulge data (use the bulge test)";
      if (!stress && lower(line).find("stretch") != std::string::npos)
        hint = "; this looks like a stress-stretch table (use uniaxial, equibiaxial or pure-shear)";
      for (size_t c = 0; c < cells.size(); ++c) {
        const std::string name = lower(cells[c]);
        const auto it = std::find(names.begin(), names.end(), name);
        if (it == names.end())
          return fail(at_line + ", column " + std::to_string(c + 1) + ": unknown column " + quoted_cell(cells[c]) + " (expected header '" +
                      expected_header(kind) + "' for " + test_kind_name(kind) + " data" + hint + ")");
        const int role = static_cast<int>(it - names.begin());
        if (seen[role]) return fail(at_line + ", column " + std::to_string(c + 1) + ": column " + quoted_cell(cells[c]) + " appears twice");
        seen[role] = true;
        role_of_column.push_back(role);
      }
      for (int role = 0; role < 2; ++role) {
        if (!seen[role]) {
          return fail(at_line + ": header has no column '" + (stress ? std::string(role == 0 ? "stretch" : "nominal_stress_MPa") : names[role]) +
                      "' (expected header '" + expected_header(kind) + "' for " + test_kind_name(kind) + " data" + hint + ")");
        }
      }
      continue;
    }
    if (cells.size() != role_of_column.size())
      return fail(at_line + ": expected " + std::to_string(role_of_column.size()) + " cells, found " + std::to_string(cells.size()));
    double values[3] = {0.0, 0.0, 0.0};
    for (size_t c = 0; c < cells.size(); ++c) {
      const std::string at_cell = at_line + ", column " + std::to_string(c + 1);
      const std::string& text = cells[c];
      if (text.empty()) return fail(at_cell + ": empty cell");
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') return fail(at_cell + ": " + quoted_cell(text) + " is not a number");
      if (!std::isfinite(value)) return fail(at_cell + ": " + quoted_cell(text) + " is not a finite number");
      values[role_of_column[c]] = value;
    }
    if (stress && values[0] <= 0.0) return fail(at_line + ", column 1: stretch " + number_text(values[0]) + " must be positive");
    if (stress && values[0] < 1.0) {
      ++set.dropped_compression_points;  // compression branch: membranes are fitted on tension only
      continue;
    }
    set.x.push_back(values[0]);
    set.y.push_back(values[1]);
    if (!stress && role_of_column.size() == 3) set.apex_height_mm.push_back(values[2]);
    line_of_row.push_back(line_number);
  }
  if (!have_header) return fail("no header row: the text has only comments (expected header '" + expected_header(kind) + "')");
  if (set.x.empty()) {
    if (set.dropped_compression_points > 0)
      return fail("no data rows with stretch >= 1 (" + dropped_compression_text(set.dropped_compression_points) + ")");
    return fail("no data rows after the header");
  }
  const auto where = [&](size_t i) { return "line " + std::to_string(line_of_row[i]); };
  if (auto problem = validate(set, where); !problem.empty()) return fail(problem);
  return set;
}

std::string measurement_problem(const MeasurementSet& set) {
  const auto where = [](size_t i) { return "point " + std::to_string(i + 1); };
  if (auto problem = validate(set, where); !problem.empty()) return problem;
  if (set.kind == TestKind::Bulge) {
    if (!(set.disc_radius_mm > 0.0 && std::isfinite(set.disc_radius_mm))) return "bulge data needs a disc radius > 0 mm";
    if (set.disc_radius_mm > MAX_DISC_RADIUS_MM)
      return "bulge data: a disc radius of " + number_text(set.disc_radius_mm) + " mm is larger than any rig (at most 1e+06 mm)";
    if (!(set.thickness_mm > 0.0 && std::isfinite(set.thickness_mm))) return "bulge data needs a disc thickness > 0 mm";
    if (auto problem = thickness_problem(set.thickness_mm); !problem.empty()) return "bulge data: disc " + problem;
    // The disc's rest shape is as wide as the opening: the balloon's thin-sheet rule, on its diameter.
    const double diameter_mm = 2.0 * set.disc_radius_mm;
    if (!within_thin_sheet_limit(set.thickness_mm, diameter_mm))
      return "bulge data: a disc " + number_text(set.thickness_mm) + " mm thick over an opening of radius " +
             number_text(set.disc_radius_mm) + " mm is no thin sheet: the membrane model needs the thickness at most " +
             number_text(100.0 * MAX_THICKNESS_PER_DIAGONAL) + "% of the opening's diameter (" +
             number_text(MAX_THICKNESS_PER_DIAGONAL * diameter_mm) + " mm here)";
  }
  return "";
}

}  // namespace balloon
