#pragma once
/// Measured rubber data: stress-stretch tables of homogeneous tests and pressure-extension curves of the
/// bulge (clamped-disc inflation) test, parsed from CSV text. Core reads no files: callers pass the text.
#include <string>
#include <vector>

#include "result.hpp"

namespace balloon {

/// The laboratory test a measurement set comes from.
///  - Bulge: clamped disc inflated by pressure; x = mean extension ratio sqrt(A/A0), y = pressure (kPa).
///  - Uniaxial / Equibiaxial / PureShear: x = loading stretch, y = nominal stress (MPa, force per rest area).
enum class TestKind { Bulge, Uniaxial, Equibiaxial, PureShear };

/// CLI name of a test kind: "bulge", "uniaxial", "equibiaxial", "pure-shear".
std::string test_kind_name(TestKind kind);
/// Parses a CLI test name; fails with a message listing the known names.
Result<TestKind> parse_test_kind(const std::string& name);

/// One measured curve, rows in loading order (x strictly increasing).
struct MeasurementSet {
  TestKind kind = TestKind::Uniaxial;
  std::vector<double> x;  ///< #points: stretch (stress tables) or mean extension ratio (bulge), >= 1
  std::vector<double> y;  ///< #points: nominal stress (MPa, stress tables) or pressure (kPa, bulge), >= 0
  std::vector<double> apex_height_mm;  ///< bulge only: #points apex heights (mm), or empty when not measured
  double disc_radius_mm = 0.0;         ///< bulge only: radius of the clamped opening (mm)
  double thickness_mm = 0.0;           ///< bulge only: rest thickness of the disc (mm)
  std::string label;                   ///< e.g. the file name, used in reports
  int dropped_compression_points = 0;  ///< stress tables: rows with stretch < 1 left out by the parser
};

/// Parses CSV text into a measurement set of the given kind.
///
/// Format: a leading UTF-8 byte order mark is ignored; blank lines and lines starting with `#` are skipped;
/// the first other line is the header.
///  - stress tables (uniaxial, equibiaxial, pure-shear): columns `stretch,nominal_stress_MPa`
///  - bulge: columns `pressure_kpa,extension_ratio` and optionally `apex_height_mm`
/// Column names are matched case-insensitively and may come in any order; unknown columns are errors.
/// Rules (each violation fails with a message naming the line, and the column where it applies):
///  - every cell is a finite number ("line 5, column 2: 'abc' is not a number");
///  - stress tables: stretch > 0; rows with stretch < 1 (the compression branch) are dropped and counted
///    in dropped_compression_points; the remaining stretches strictly increase row by row; stress >= 0 for
///    stretch >= 1; and the stress never falls more than 10% of the table's stress range below an earlier
///    row (a larger drop is not digitising noise but a broken table);
///  - bulge: pressure >= 0, extension ratio >= 1, apex height >= 0; extension ratios strictly increase
///    row by row (rows in inflation order; the pressure may fall past a pressure maximum, as in a
///    volume-controlled test), and the pressure at the last row exceeds the pressure at the first (the disc
///    inflates as the pressure rises overall);
///  - no stretch or extension ratio above 20 (rubbers break below about 10: such a column is likely the
///    elongation in percent);
///  - at least 2 rows remain (a single point cannot fit a curve).
/// disc_radius_mm and thickness_mm are not in the CSV: the caller sets them for bulge data.
Result<MeasurementSet> parse_measurements(const std::string& csv_text, TestKind kind, const std::string& label = "");

/// Checks a set built in code (same rules as the parser, plus, for bulge sets, a disc radius > 0 and a
/// thickness of at least MIN_THICKNESS_MM and at most the thin-sheet limit of the opening's diameter,
/// material/thin_sheet.hpp); returns an empty string when it is usable for fitting.
std::string measurement_problem(const MeasurementSet& set);

}  // namespace balloon
