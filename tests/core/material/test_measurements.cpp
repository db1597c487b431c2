#include "material/measurements.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace balloon {
namespace {

std::string read_data(const std::string& name) {
  std::ifstream in(std::string(BALLOON_TEST_DATA_DIR) + "/materials/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Parses and expects a failure whose message contains `expected`.
void expect_error(const std::string& csv, TestKind kind, const std::string& expected) {
  const auto parsed = parse_measurements(csv, kind);
  ASSERT_FALSE(parsed.ok()) << "accepted:\n" << csv;
  EXPECT_NE(parsed.error().find(expected), std::string::npos) << "message: " << parsed.error() << "\nexpected: " << expected;
}

TEST(Measurements, ParsesEveryRealTable) {
  struct Case {
    const char* file;
    TestKind kind;
    size_t points;
    int dropped;
    double first_x, last_y;
  };
  const Case cases[] = {
      {"treloar1944_ut.csv", TestKind::Uniaxial, 24, 0, 1.02, 6.3176},
      {"treloar1944_et.csv", TestKind::Equibiaxial, 16, 0, 1.027, 2.4426},
      {"treloar1944_ps.csv", TestKind::PureShear, 13, 0, 1.03, 1.8050},
      {"meunier2008_silicone_ut.csv", TestKind::Uniaxial, 17, 16, 1.0, 0.7972},  // 33 rows, 16 in compression
      {"meunier2008_silicone_et.csv", TestKind::Equibiaxial, 14, 0, 1.0, 1.3204},
      {"meunier2008_silicone_ps.csv", TestKind::PureShear, 19, 0, 1.0, 0.9023},
  };
  for (const auto& c : cases) {
    const auto text = read_data(c.file);
    ASSERT_FALSE(text.empty()) << c.file;
    const auto set = parse_measurements(text, c.kind, c.file);
    ASSERT_TRUE(set.ok()) << c.file << ": " << set.error();
    EXPECT_EQ(set->x.size(), c.points) << c.file;
    EXPECT_EQ(set->y.size(), c.points) << c.file;
    EXPECT_EQ(set->dropped_compression_points, c.dropped) << c.file;
    EXPECT_DOUBLE_EQ(set->x.front(), c.first_x) << c.file;
    EXPECT_DOUBLE_EQ(set->y.back(), c.last_y) << c.file;
    EXPECT_EQ(set->label, c.file);
    EXPECT_EQ(set->kind, c.kind);
  }
}

TEST(Measurements, ParsesBulgeDataWithOptionalApexHeightInAnyColumnOrder) {
  const auto plain = parse_measurements("# my rig\npressure_kpa,extension_ratio\n0,1\n1.5,1.1\n2.5,1.3\n", TestKind::Bulge);
  ASSERT_TRUE(plain.ok()) << plain.error();
  EXPECT_EQ(plain->x, (std::vector<double>{1.0, 1.1, 1.3}));
  EXPECT_EQ(plain->y, (std::vector<double>{0.0, 1.5, 2.5}));
  EXPECT_TRUE(plain->apex_height_mm.empty());

  const auto with_apex =
      parse_measurements("Extension_Ratio , Pressure_kPa, apex_height_mm\r\n1.0,0,0\r\n1.2,2,13.3\r\n\r\n1.5,2.1,20\r\n", TestKind::Bulge);
  ASSERT_TRUE(with_apex.ok()) << with_apex.error();
  EXPECT_EQ(with_apex->x, (std::vector<double>{1.0, 1.2, 1.5}));
  EXPECT_EQ(with_apex->y, (std::vector<double>{0.0, 2.0, 2.1}));
  EXPECT_EQ(with_apex->apex_height_mm, (std::vector<double>{0.0, 13.3, 20.0}));
}

TEST(Measurements, PressureMayFallPastAMaximumAsInVolumeControl) {
  const auto set = parse_measurements("pressure_kpa,extension_ratio\n1,1.1\n3,1.4\n2.5,1.8\n2.8,2.4\n", TestKind::Bulge);
  EXPECT_TRUE(set.ok()) << set.error();
}

TEST(Measurements, BadInputGivesClearErrors) {
  const std::string header = "stretch,nominal_stress_MPa\n";
  expect_error("", TestKind::Uniaxial, "no data: the text is empty");
  expect_error("  \n\n", TestKind::Uniaxial, "no data: the text is empty");
  expect_error("# only a comment\n", TestKind::Uniaxial, "no header row");
  expect_error(header, TestKind::Uniaxial, "no data rows");
  expect_error("stretch\n1.1\n1.2\n", TestKind::Uniaxial, "line 1: header has no column 'nominal_stress_MPa'");
  expect_error("stretch,stress\n1.1,0.1\n", TestKind::Uniaxial, "line 1, column 2: unknown column 'stress'");
  expect_error("pressure_kpa,extension_ratio\n1,1.1\n", TestKind::Uniaxial, "looks like bulge data");
  expect_error("# c\n# c\n" + header + "1.1,0.1\nabc,0.2\n", TestKind::Uniaxial, "line 5, column 1: 'abc' is not a number");
  expect_error("# c\n# c\n" + header + "1.1,0.1\n1.2,abc\n", TestKind::Uniaxial, "line 5, column 2: 'abc' is not a number");
  expect_error(header + "1.1,0.1x\n1.2,0.2\n", TestKind::Uniaxial, "line 2, column 2: '0.1x' is not a number");
  // Values no rubber gives (a unit slip, or hostile): named with the range, not left to the fit, whose
  // optimizer found "no starting point" for them.
  expect_error(header + "1.1,1e300\n1.2,1e300\n", TestKind::Uniaxial,
               "the largest nominal stress, 1e+300 MPa, is outside what a rubber gives (1e-07 to 100000 MPa)");
  expect_error(header + "1.1,1e-300\n1.2,2e-300\n", TestKind::Uniaxial, "are the units MPa?");
  expect_error("pressure_kpa,extension_ratio\n1e9,1.1\n2e9,1.2\n", TestKind::Bulge, "are the units kPa?");
  {
    // A huge cell is quoted by its first 40 characters: the message stays one short line.
    const auto parsed = parse_measurements(header + "1.1," + std::string(100000, '7') + "x\n1.2,0.2\n", TestKind::Uniaxial);
    ASSERT_FALSE(parsed.ok());
    EXPECT_NE(parsed.error().find("line 2, column 2: '" + std::string(40, '7') + "...' is not a number"), std::string::npos)
        << parsed.error().substr(0, 200);
    EXPECT_LT(parsed.error().size(), 120u);
  }
  expect_error(header + "1.1,inf\n1.2,0.2\n", TestKind::Uniaxial, "line 2, column 2: 'inf' is not a finite number");
  expect_error(header + "1.1,nan\n1.2,0.2\n", TestKind::Uniaxial, "line 2, column 2: 'nan' is not a finite number");
  expect_error(header + "1.1,\n1.2,0.2\n", TestKind::Uniaxial, "line 2, column 2: empty cell");
  expect_error(header + "1.1,0.1,7\n", TestKind::Uniaxial, "line 2: expected 2 cells, found 3");
  expect_error(header + "1.1,0.1\n", TestKind::Uniaxial, "only 1 data point");
  // Rows of stretch below 1 are dropped, and the message says so (with the strain-for-stretch mix-up).
  expect_error(header + "0.8,-0.1\n1.1,0.1\n", TestKind::Uniaxial,
               "only 1 data point (at least 2 are needed to fit a curve); 1 row with stretch below 1 dropped");
  expect_error(header + "0.8,-0.1\n0.9,-0.05\n", TestKind::Uniaxial,
               "no data rows with stretch >= 1 (2 rows with stretch below 1 dropped: compression is not fitted; if the "
               "column holds the strain dL/L0, give the stretch 1 + strain)");
  // A stretch no rubber reaches is likely an elongation in percent (the fit said "no starting point of
  // hart-smith reproduces the data's sign (are the values positive?)" at 200).
  expect_error(header + "1.2,0.2\n1.4,0.3\n200,1\n", TestKind::Uniaxial,
               "line 4: stretch 200 is beyond any rubber (rubbers break below a stretch of about 10; at most 20 is "
               "accepted): is the column the elongation in percent?");
  expect_error(header + "-1,0.1\n1.1,0.1\n", TestKind::Uniaxial, "line 2, column 1: stretch -1 must be positive");
  expect_error(header + "1.1,0.1\n1.3,0.3\n1.2,0.35\n", TestKind::Uniaxial, "line 4: stretch 1.2 is not larger than the previous row's 1.3");
  expect_error(header + "1.1,0.1\n1.1,0.2\n", TestKind::Uniaxial, "line 3: stretch 1.1 is not larger");
  expect_error(header + "1.1,-0.1\n1.2,0.2\n", TestKind::Uniaxial, "line 2: negative nominal stress -0.1 MPa");
  expect_error(header + "1.1,0.1\n1.2,1.0\n1.3,0.5\n1.4,1.2\n", TestKind::Uniaxial, "line 4: nominal stress 0.5 MPa falls far below");

  const std::string bulge = "pressure_kpa,extension_ratio\n";
  expect_error(bulge + "-2,1.1\n3,1.2\n", TestKind::Bulge, "line 2: negative pressure -2 kPa");
  expect_error(bulge + "1,0.9\n3,1.2\n", TestKind::Bulge, "line 2: extension ratio 0.9 < 1");
  expect_error(bulge + "1,1.3\n3,1.2\n", TestKind::Bulge, "line 3: extension ratio 1.2 is not larger than the previous row's 1.3");
  expect_error(bulge + "5,1.1\n3,1.2\n2,1.5\n", TestKind::Bulge, "must grow with pressure overall");
  expect_error(bulge + "1,1.1\n", TestKind::Bulge, "only 1 data point");
  expect_error(bulge + "1,1.1\n3,25\n", TestKind::Bulge, "line 3: extension ratio 25 is beyond any rubber");
  expect_error("pressure_kpa\n1\n2\n", TestKind::Bulge, "header has no column 'extension_ratio'");
  expect_error("stretch,nominal_stress_MPa\n1.1,0.1\n", TestKind::Bulge, "looks like a stress-stretch table");
  expect_error(bulge.substr(0, bulge.size() - 1) + ",apex_height_mm\n1,1.1,-3\n2,1.2,4\n", TestKind::Bulge,
               "line 2: apex height must be a finite number >= 0 mm");
}

TEST(Measurements, ASpreadsheetsByteOrderMarkIsNotPartOfTheHeader) {
  // Spreadsheets' "CSV UTF-8" starts with one; it was read as part of the name: "unknown column '?stretch'".
  const auto parsed = parse_measurements("\xEF\xBB\xBFstretch,nominal_stress_MPa\n1.2,0.2\n1.4,0.3\n", TestKind::Uniaxial);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed->x, (std::vector<double>{1.2, 1.4}));
  EXPECT_EQ(parsed->y, (std::vector<double>{0.2, 0.3}));
}

TEST(Measurements, ABulgeDiscMustBeAThinSheetOfAtLeastAMicrometre) {
  MeasurementSet set;
  set.kind = TestKind::Bulge;
  set.x = {1.1, 1.3};
  set.y = {1.0, 2.0};
  set.disc_radius_mm = 15;
  set.thickness_mm = 3.0;  // 10% of the 30 mm opening: the limit passes
  EXPECT_EQ(measurement_problem(set), "");
  // Both were fitted before: 20 mm as if it were a membrane, 1e-300 mm into "no starting point reproduces
  // the data's sign".
  set.thickness_mm = 20.0;
  EXPECT_EQ(measurement_problem(set),
            "bulge data: a disc 20 mm thick over an opening of radius 15 mm is no thin sheet: the membrane model needs "
            "the thickness at most 10% of the opening's diameter (3 mm here)");
  set.thickness_mm = 1e-300;
  EXPECT_NE(measurement_problem(set).find("bulge data: disc thickness must be a positive number of mm, at least 0.001"),
            std::string::npos)
      << measurement_problem(set);
}

TEST(Measurements, ProblemCheckCoversSetsBuiltInCode) {
  MeasurementSet set;
  set.kind = TestKind::Bulge;
  set.x = {1.1, 1.3};
  set.y = {1.0, 2.0};
  EXPECT_EQ(measurement_problem(set), "bulge data needs a disc radius > 0 mm");
  set.disc_radius_mm = 30;
  EXPECT_EQ(measurement_problem(set), "bulge data needs a disc thickness > 0 mm");
  set.thickness_mm = 0.5;
  EXPECT_EQ(measurement_problem(set), "");
  set.disc_radius_mm = 1e300;  // the fit only said "no starting point reproduces the data's sign"
  EXPECT_NE(measurement_problem(set).find("larger than any rig"), std::string::npos);
  set.disc_radius_mm = 30;
  set.y = {1.0};
  EXPECT_NE(measurement_problem(set).find("2 x values but 1 y values"), std::string::npos);
}

TEST(Measurements, TestKindNamesRoundTrip) {
  for (auto kind : {TestKind::Bulge, TestKind::Uniaxial, TestKind::Equibiaxial, TestKind::PureShear}) {
    const auto parsed = parse_test_kind(test_kind_name(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, kind);
  }
  const auto bad = parse_test_kind("biaxial");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("known: bulge, uniaxial, equibiaxial, pure-shear"), std::string::npos);
}

}  // namespace
}  // namespace balloon
