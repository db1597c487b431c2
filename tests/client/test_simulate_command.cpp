// `balloon simulate` checked from outside, as issue 2's CLI contract states it: exit codes, the JSON
// keys, one-line errors, and no partial output file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_test_support.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon::testing {
namespace {

class SimulateCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_scratch = new ScratchDir();
    // 642 vertices: big enough for the closed-form check below, small enough to run in ~0.1 s.
    const ProcessResult made = run_balloon(*s_scratch, {"mesh", "sphere", "--radius", "10", "--subdivisions", "3",
                                                        "--out", s_scratch->file("sphere.obj")});
    ASSERT_EQ(made.exit_code, 0) << made.err;
  }
  static void TearDownTestSuite() {
    delete s_scratch;
    s_scratch = nullptr;
  }
  static std::string sphere() { return s_scratch->file("sphere.obj"); }
  ProcessResult run(const std::vector<std::string>& args) { return run_balloon(*s_scratch, args); }

  /// Runs `args` expecting a bad-input failure: exit 2, nothing on stdout, ONE line on stderr that
  /// contains `needle`.
  void expect_bad_input(const std::vector<std::string>& args, const std::string& needle) {
    const ProcessResult result = run(args);
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
    const auto lines = split_lines(result.err);
    ASSERT_EQ(lines.size(), 1u) << result.err;
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << lines[0] << "' does not mention '" << needle << "'";
  }

  static ScratchDir* s_scratch;
};
ScratchDir* SimulateCommand::s_scratch = nullptr;

TEST_F(SimulateCommand, JsonHasTheContractKeysAndReachesTheVolumeRatio) {
  const ProcessResult result = run({"simulate", sphere(), "--material", "latex", "--volume-ratio", "8", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto lines = split_lines(result.out);
  ASSERT_EQ(lines.size(), 1u) << "one JSON object on one line expected:\n" << result.out;
  const std::string& json = lines[0];
  ASSERT_EQ(json.front(), '{');
  ASSERT_EQ(json.back(), '}');
  for (const char* key : {"converged", "pressure_kpa", "volume_mm3", "rest_volume_mm3", "volume_ratio", "mean_stretch",
                          "max_stretch", "newton_iterations", "residual_norm", "time_s", "vertices", "factorizations",
                          "load_steps", "message", "material", "thickness_mm", "flipped_orientation", "unstable_modes"})
    EXPECT_TRUE(json_field(json, key).has_value()) << "missing key " << key;
  EXPECT_EQ(json_field(json, "converged"), "true");
  EXPECT_EQ(json_field(json, "stop_reason"), "\"converged\"");
  EXPECT_GE(json_number_field(json, "unstable_modes"), 0);
  EXPECT_EQ(json_number_field(json, "vertices"), 642);
  EXPECT_NEAR(json_number_field(json, "volume_ratio"), 8.0, 1e-6);
  EXPECT_NEAR(json_number_field(json, "volume_mm3") / json_number_field(json, "rest_volume_mm3"), 8.0, 1e-6);
  // A sphere stays a sphere: the area-mean stretch is the cube root of the volume ratio (tolerance 1e-3).
  EXPECT_NEAR(json_number_field(json, "mean_stretch"), 2.0, 1e-3);
  EXPECT_GT(json_number_field(json, "pressure_kpa"), 0.0);
  EXPECT_EQ(json_number_field(json, "thickness_mm"), 0.5);  // the default
  EXPECT_EQ(json_field(json, "flipped_orientation"), "false");
}

TEST_F(SimulateCommand, PressureIsInKilopascalsAgainstTheThinSphereLaw) {
  // Neo-Hookean thin sphere: p = 2 mu h / R (1/l - 1/l^7) (MPa). At mu = 0.3 MPa, h = 0.5 mm, R = 10 mm and
  // V/V0 = 8 (l = 2): p = 14.7656 kPa. 642 vertices resolve it to about 1%; 3% tolerance catches unit
  // errors (a factor 1000) and wrong thickness defaults (a factor 2) alike.
  const ProcessResult result =
      run({"simulate", sphere(), "--material", "neo-hookean:mu=0.3", "--volume-ratio", "8", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const double expected_kpa = 2.0 * 0.3 * 0.5 / 10.0 * (0.5 - 1.0 / 128.0) * 1000.0;
  EXPECT_NEAR(json_number_field(result.out, "pressure_kpa"), expected_kpa, 0.03 * expected_kpa);
}

TEST_F(SimulateCommand, PressureControlWritesTheInflatedMeshOnSuccess) {
  const std::string out = s_scratch->file("inflated.ply");
  const ProcessResult result = run({"simulate", sphere(), "--material", "neo-hookean:mu=0.3", "--thickness", "0.5",
                                    "--pressure", "10", "--out", out, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NEAR(json_number_field(result.out, "pressure_kpa"), 10.0, 1e-9);
  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_GT(std::filesystem::file_size(out), 642u * 24u);  // binary PLY holds 642 double positions at least
}

TEST_F(SimulateCommand, HumanSummaryStatesUnits) {
  const ProcessResult result = run({"simulate", sphere(), "--material", "silicone", "--volume-ratio", "2"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("kPa"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("mm^3"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("converged"), std::string::npos) << result.out;
}

TEST_F(SimulateCommand, TheSummarySaysHowMuchOfTheBalloonIsWhereItsRubbersPressureFalls) {
  // Latex's pressure falls between stretch 1.365 and 3.966; the sphere at x8 stretches by about 2 everywhere.
  const ProcessResult past = run({"simulate", sphere(), "--material", "latex", "--volume-ratio", "8"});
  ASSERT_EQ(past.exit_code, 0) << past.err;
  EXPECT_NE(past.out.find("rubber         its pressure falls as it stretches between stretch 1.365 and 3.966 "
                          "(volume ratio 2.55 to 62.4); 100% of the inflated surface is stretched there: "),
            std::string::npos)
      << past.out;
  EXPECT_NE(past.out.find("a volume ratio below 2.55 or above 62.4 keeps the sheet out of it"), std::string::npos)
      << past.out;
  const ProcessResult json = run({"simulate", sphere(), "--material", "silicone", "--volume-ratio", "8", "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const std::optional<std::string> band = json_field(json.out, "pressure_fall");
  ASSERT_TRUE(band) << json.out;
  EXPECT_NEAR(json_number_field(*band, "from_stretch"), 1.406, 2e-3) << *band;
  EXPECT_NEAR(json_number_field(*band, "to_stretch"), 1.620, 2e-3) << *band;
  EXPECT_EQ(json_number_field(*band, "area_share"), 0.0) << *band;  // x8 is past silicone's band
}

TEST_F(SimulateCommand, NotConvergedPrintsTheResultExitsThreeAndWritesNoFile) {
  // 20 kPa is above this neo-Hookean sphere's pressure maximum (about 18.6 kPa): no equilibrium exists.
  const std::string out = s_scratch->file("never.obj");
  const ProcessResult result =
      run({"simulate", sphere(), "--material", "neo-hookean:mu=0.3", "--pressure", "20", "--out", out, "--json"});
  EXPECT_EQ(result.exit_code, 3) << result.err;
  EXPECT_EQ(json_field(result.out, "converged"), "false") << result.out;
  EXPECT_EQ(json_field(result.out, "stop_reason"), "\"above_max_pressure\"") << result.out;
  EXPECT_TRUE(json_field(result.out, "residual_norm").has_value());
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(SimulateCommand, SizeScalesAMeshDrawnInOtherUnitsToMillimetres) {
  // The suite's 10 mm sphere drawn in centimetres: 1 unit across radius, read as 1 mm, is refused (a
  // 0.5 mm sheet on a 3.4 mm balloon), and `--size` with the 10 mm sphere's diagonal makes it that sphere:
  // the same rest volume and the thin-sphere pressure of the test above.
  const ProcessResult made = run({"mesh", "sphere", "--radius", "1", "--subdivisions", "3", "--out", s_scratch->file("cm.obj")});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  expect_bad_input({"simulate", s_scratch->file("cm.obj"), "--material", "neo-hookean:mu=0.3", "--volume-ratio", "8"},
                   "--size MM");
  const Result<TriMesh> millimetres = read_mesh(sphere());
  ASSERT_TRUE(millimetres) << millimetres.error();
  std::ostringstream size;
  size.precision(17);
  size << bounding_box_diagonal(millimetres->vertices);
  const ProcessResult scaled = run({"simulate", s_scratch->file("cm.obj"), "--material", "neo-hookean:mu=0.3", "--size",
                                    size.str(), "--volume-ratio", "8", "--json"});
  ASSERT_EQ(scaled.exit_code, 0) << scaled.err;
  const ProcessResult reference = run({"simulate", sphere(), "--material", "neo-hookean:mu=0.3", "--volume-ratio", "8", "--json"});
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  EXPECT_NEAR(json_number_field(scaled.out, "rest_volume_mm3"), json_number_field(reference.out, "rest_volume_mm3"),
              1e-9 * json_number_field(reference.out, "rest_volume_mm3"));
  EXPECT_NEAR(json_number_field(scaled.out, "pressure_kpa"), json_number_field(reference.out, "pressure_kpa"),
              1e-6 * json_number_field(reference.out, "pressure_kpa"));
  expect_bad_input({"simulate", sphere(), "--material", "latex", "--volume-ratio", "2", "--size", "-10"},
                   "--size: size must be a number of mm");
}

TEST_F(SimulateCommand, InwardMeshIsFlippedAndSaysSo) {
  // The same sphere with every face reversed.
  const ProcessResult made = run({"mesh", "sphere", "--radius", "5", "--subdivisions", "2", "--out", s_scratch->file("s.obj")});
  ASSERT_EQ(made.exit_code, 0);
  std::ifstream in(s_scratch->file("s.obj"));
  std::ofstream flipped(s_scratch->file("inward.obj"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("f ", 0) == 0) {
      std::istringstream words(line.substr(2));
      std::string a, b, c;
      words >> a >> b >> c;
      flipped << "f " << a << " " << c << " " << b << "\n";
    } else {
      flipped << line << "\n";
    }
  }
  flipped.close();
  const ProcessResult result =
      run({"simulate", s_scratch->file("inward.obj"), "--material", "latex", "--volume-ratio", "2", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(json_field(result.out, "flipped_orientation"), "true");
  EXPECT_GT(json_number_field(result.out, "rest_volume_mm3"), 0.0);
}

TEST_F(SimulateCommand, BadInputIsOneLineAndExitTwo) {
  const std::string s = sphere();
  expect_bad_input({"simulate", s_scratch->file("missing.obj"), "--material", "latex", "--pressure", "1"}, "missing.obj");
  expect_bad_input({"simulate", s, "--material", "rubber", "--pressure", "1"}, "rubber");
  expect_bad_input({"simulate", s, "--material", "neo-hookean:mu=-1", "--pressure", "1"}, "mu");
  expect_bad_input({"simulate", s, "--material", "latex", "--thickness", "-0.5", "--pressure", "1"}, "thickness");
  expect_bad_input({"simulate", s, "--material", "latex", "--thickness", "0", "--pressure", "1"}, "thickness");
  expect_bad_input({"simulate", s, "--material", "latex", "--pressure", "1", "--volume-ratio", "2"}, "not both");
  expect_bad_input({"simulate", s, "--material", "latex"}, "pressure");
  expect_bad_input({"simulate", s, "--material", "latex", "--volume-ratio", "0"}, "volume ratio");
  expect_bad_input({"simulate", s, "--material", "latex", "--volume-ratio", "-2"}, "volume ratio");
  expect_bad_input({"simulate", s, "--material", "latex", "--volume-ratio", "nan"}, "finite");
  expect_bad_input({"simulate", s, "--material", "latex", "--pressure", "inf"}, "finite");
  expect_bad_input({"simulate", s, "--material", "latex", "--pressure", "abc"}, "not a number");
  expect_bad_input({"simulate", s, "--material", "latex", "--pressure", "1", "--frobnicate"}, "--frobnicate");
  expect_bad_input({"simulate", s, "--pressure", "1"}, "--material");
  expect_bad_input({"simulate", "--material", "latex", "--pressure", "1"}, "REST_MESH");
  expect_bad_input({"simulate", s, "--material", "latex", "--pressure", "1", "--out", s_scratch->file("x.xyz")}, ".obj");
}

TEST_F(SimulateCommand, InvalidMeshesAreRejectedWithTheProblemNamed) {
  std::ofstream(s_scratch->file("open.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\n";
  expect_bad_input({"simulate", s_scratch->file("open.obj"), "--material", "latex", "--pressure", "1"}, "open");
  std::ofstream(s_scratch->file("garbage.obj")) << "this is not a mesh\n";
  expect_bad_input({"simulate", s_scratch->file("garbage.obj"), "--material", "latex", "--pressure", "1"}, "garbage.obj");
  std::ofstream(s_scratch->file("nan.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  const ProcessResult result = run({"simulate", s_scratch->file("nan.obj"), "--material", "latex", "--pressure", "1"});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(split_lines(result.err).size(), 1u) << result.err;
}

TEST_F(SimulateCommand, HelpDocumentsExitCodes) {
  const ProcessResult top = run({"--help"});
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("simulate"), std::string::npos);
  EXPECT_NE(top.out.find("Exit codes"), std::string::npos);
  const ProcessResult sub = run({"simulate", "--help"});
  EXPECT_EQ(sub.exit_code, 0);
  EXPECT_NE(sub.out.find("--volume-ratio"), std::string::npos);
  EXPECT_NE(sub.out.find("3 not converged"), std::string::npos);
  const ProcessResult unknown = run({"frobnicate"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_EQ(split_lines(unknown.err).size(), 1u);
}

}  // namespace
}  // namespace balloon::testing
