// `balloon design` checked from outside, as issue 4's CLI contract states it: bad input is one line and
// exit 2 before any work; a small design writes the five files with the contract's keys and columns.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_test_support.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon::testing {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class DesignCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_scratch = new ScratchDir();
    // A bumpy icosphere (162 vertices, radius ~10 mm): not a shape a uniform inflation reproduces, so the
    // design has work to do, and small enough to design in about a second.
    TriMesh bumpy = make_icosphere(1.0, 2);
    for (int i = 0; i < bumpy.vertex_count(); ++i) {
      const Eigen::Vector3d p = bumpy.vertices.row(i);
      bumpy.vertices.row(i) = 10.0 * (1.0 + 0.08 * std::sin(3 * p.x()) * std::sin(2 * p.y()) * std::cos(4 * p.z())) * p;
    }
    ASSERT_TRUE(write_mesh(bumpy, s_scratch->file("bumpy.obj")).ok());
    std::ofstream(s_scratch->file("open.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\n";
    std::ofstream(s_scratch->file("garbage.obj")) << "\x01\x02 this is not a mesh \xff\n";
  }
  static void TearDownTestSuite() {
    delete s_scratch;
    s_scratch = nullptr;
  }
  static std::string bumpy() { return s_scratch->file("bumpy.obj"); }
  ProcessResult run(const std::vector<std::string>& args) { return run_balloon(*s_scratch, args); }

  /// Runs `args` expecting a bad-input failure: exit 2, nothing on stdout, ONE line on stderr that
  /// contains `needle`, and no output directory created for the run.
  void expect_bad_input(std::vector<std::string> args, const std::string& needle) {
    const std::string out_dir = s_scratch->file("bad-out");
    args.push_back("--out-dir");
    args.push_back(out_dir);
    const ProcessResult result = run(args);
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
    const auto lines = split_lines(result.err);
    ASSERT_EQ(lines.size(), 1u) << result.err;
    EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << lines[0] << "' does not mention '" << needle << "'";
    EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(out_dir) / "report.json"));
  }

  static ScratchDir* s_scratch;
};
ScratchDir* DesignCommand::s_scratch = nullptr;

TEST_F(DesignCommand, BadInputIsOneLineAndExitTwo) {
  const std::string s = bumpy();
  expect_bad_input({"design", s_scratch->file("missing.obj"), "--material", "silicone"}, "missing.obj");
  expect_bad_input({"design", s_scratch->file("open.obj"), "--material", "silicone", "--resolution", "0"}, "open");
  expect_bad_input({"design", s_scratch->file("garbage.obj"), "--material", "silicone"}, "garbage.obj");
  expect_bad_input({"design", s, "--material", "rubber"}, "rubber");
  expect_bad_input({"design", s, "--material", "neo-hookean:mu=-1"}, "mu");
  expect_bad_input({"design", s}, "--material");
  expect_bad_input({"design", "--material", "silicone"}, "TARGET_MESH");
  expect_bad_input({"design", s, "--material", "silicone", "--scale", "0.5", "--volume-ratio", "8"}, "not both");
  expect_bad_input({"design", s, "--material", "silicone", "--thickness", "-0.5"}, "thickness");
  expect_bad_input({"design", s, "--material", "silicone", "--scale", "0"}, "scale");
  expect_bad_input({"design", s, "--material", "silicone", "--volume-ratio", "-8"}, "volume ratio");
  expect_bad_input({"design", s, "--material", "silicone", "--size", "-100"}, "size");
  expect_bad_input({"design", s, "--material", "silicone", "--resolution", "-5"}, "resolution");
  expect_bad_input({"design", s, "--material", "silicone", "--method", "gradient-descent"}, "method");
  expect_bad_input({"design", s, "--material", "silicone", "--nozzle", "1,2"}, "nozzle");
  expect_bad_input({"design", s, "--material", "silicone", "--nozzle", "0,0,-10,-1"}, "nozzle");
  // A nozzle far from the surface is most likely a typo or wrong units: refused before the design runs.
  expect_bad_input({"design", s, "--material", "silicone", "--resolution", "0", "--nozzle", "0,0,-500"}, "nozzle");
  expect_bad_input({"design", s, "--material", "silicone", "--max-time", "-1"}, "max time");
  expect_bad_input({"design", s, "--material", "silicone", "--tolerance-samples", "-1"}, "tolerance-samples");
  expect_bad_input({"design", s, "--material", "silicone", "--frobnicate"}, "--frobnicate");
  // The flag is found by the field path the check names (design.thickness_mm), locally and from the
  // service's google.rpc.BadRequest (a resolution of 60 passes the local check, the server wants 100).
  expect_bad_input({"design", s, "--material", "silicone", "--thickness", "-0.5"}, "--thickness: ");
  expect_bad_input({"design", s, "--material", "silicone", "--resolution", "60"}, "--resolution: ");
  expect_bad_input({"design", s, "--material", "rubber"}, "--material: ");
}

TEST_F(DesignCommand, HelpNamesTheFilesAndTheDesignIsListed) {
  const ProcessResult help = run({"design", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  for (const char* word : {"rest.obj", "inflated.obj", "mold.stl", "report.json", "convergence.csv", "--out-dir"})
    EXPECT_NE(help.out.find(word), std::string::npos) << word;
  const ProcessResult top = run({"--help"});
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("design"), std::string::npos);
}

TEST_F(DesignCommand, SmallDesignWritesTheFiveFilesWithTheContractKeys) {
  const std::string out_dir = s_scratch->file("design-out");
  const ProcessResult result = run({"design", bumpy(), "--material", "silicone", "--resolution", "0", "--volume-ratio",
                                    "8", "--nozzle", "auto", "--max-time", "20", "--tolerance-samples", "1",
                                    "--out-dir", out_dir, "--json"});
  ASSERT_TRUE(result.exit_code == 0 || result.exit_code == 3) << result.err;
  const auto lines = split_lines(result.out);
  ASSERT_EQ(lines.size(), 1u) << "one JSON object on one line expected:\n" << result.out;
  const std::string& json = lines[0];
  for (const char* key : {"converged", "method", "avg_error_mm", "max_error_mm", "avg_error_rel", "max_error_rel",
                          "bbox_diag_mm", "pressure_kpa", "volume_ratio", "iterations", "time_s", "vertices",
                          "active_terms", "baseline_avg_error_mm", "baseline_max_error_mm", "preparation",
                          "material", "thickness_mm", "distance_energy", "residual_norm", "message", "tolerance",
                          "mold", "surface_weight"})
    EXPECT_TRUE(json_field(json, key).has_value()) << "missing key " << key << " in " << json;
  EXPECT_EQ(json_number_field(json, "vertices"), 162.0);
  EXPECT_NEAR(json_number_field(json, "volume_ratio"), 8.0, 0.05);
  EXPECT_GT(json_number_field(json, "pressure_kpa"), 0.0);
  const double avg = json_number_field(json, "avg_error_mm");
  const double baseline = json_number_field(json, "baseline_avg_error_mm");
  EXPECT_GT(baseline, 0.0);
  EXPECT_LT(avg, baseline);  // the design beats inflating the downscaled target
  EXPECT_NE(json_field(json, "active_terms")->find("nozzle"), std::string::npos) << json;

  const std::filesystem::path dir(out_dir);
  for (const char* name : {"rest.obj", "inflated.obj", "mold.stl", "report.json", "convergence.csv"})
    EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
  EXPECT_EQ(read_text((dir / "report.json").string()), json + "\n");

  const auto csv = split_lines(read_text((dir / "convergence.csv").string()));
  ASSERT_GE(csv.size(), 2u);
  EXPECT_EQ(csv[0], "time_s,iteration,avg_error_mm,max_error_mm,residual_norm");
  EXPECT_EQ(std::count(csv[1].begin(), csv[1].end(), ','), 4);

  const Result<TriMesh> rest = read_mesh((dir / "rest.obj").string());
  const Result<TriMesh> inflated = read_mesh((dir / "inflated.obj").string());
  const Result<TriMesh> mold = read_mesh((dir / "mold.stl").string());
  ASSERT_TRUE(rest.ok() && inflated.ok() && mold.ok());
  EXPECT_EQ(rest->vertex_count(), 162);
  EXPECT_EQ(inflated->vertex_count(), 162);
  EXPECT_GT(mold->face_count(), rest->face_count());  // the tube adds faces
}

// Latex's sphere pressure falls between stretch 1.365 and 3.966. The regular icosahedron inflates onto
// itself, every triangle by the sphere's stretch cbrt(ratio), so its design is matched at once: at x8
// (stretch 2) all of it is in that band and the summary says what that means; at x2 (stretch 1.26) none.
TEST_F(DesignCommand, TheSummarySaysWhereTheRubbersPressureFallsAndHowMuchOfTheDesignIsThere) {
  const std::string icosahedron = s_scratch->file("icosahedron.obj");
  ASSERT_TRUE(write_mesh(make_icosphere(50.0, 0), icosahedron).ok());
  const ProcessResult past = run({"design", icosahedron, "--material", "latex", "--resolution", "0", "--volume-ratio",
                                  "8", "--out-dir", s_scratch->file("fall-8")});
  ASSERT_EQ(past.exit_code, 0) << past.err;
  // The maximum is at stretch 1.3654, a volume ratio of 2.546.
  EXPECT_NE(past.out.find("rubber         its pressure falls as it stretches between stretch 1.365 and 3.966 "
                          "(volume ratio 2.55 to 62.4); 100% of the inflated surface is stretched there: "),
            std::string::npos)
      << past.out;
  EXPECT_NE(past.out.find("bulge one at a time"), std::string::npos) << past.out;
  EXPECT_NE(past.out.find("a volume ratio below 2.55 or above 62.4 keeps the sheet out of it"), std::string::npos)
      << past.out;
  const std::string json = read_text(s_scratch->file("fall-8") + "/report.json");
  const std::optional<std::string> band = json_field(json, "pressure_fall");
  ASSERT_TRUE(band) << json;
  EXPECT_NEAR(json_number_field(*band, "area_share"), 1.0, 1e-12) << *band;
  EXPECT_NEAR(json_number_field(*band, "from_volume_ratio"), 2.546, 2e-3) << *band;

  const ProcessResult before = run({"design", icosahedron, "--material", "latex", "--resolution", "0",
                                    "--volume-ratio", "2", "--out-dir", s_scratch->file("fall-2")});
  ASSERT_EQ(before.exit_code, 0) << before.err;
  EXPECT_NE(before.out.find("(volume ratio 2.55 to 62.4); 0% of the inflated surface is stretched there\n"),
            std::string::npos)
      << before.out;
  EXPECT_EQ(before.out.find("bulge"), std::string::npos) << before.out;
  // The help quotes latex's band: the same numbers as the report's.
  EXPECT_NE(run({"design", "--help"}).out.find("(latex: volume ratio 2.55 to 62.4, x8"), std::string::npos);
}

// A design stopped before its start was ever inflated has no error to report: report.json says null, never
// 0, and `jobs result` writes the same report.json (and the same files) for that job as `balloon design` did.
TEST_F(DesignCommand, ADesignWithoutErrorsReportsNullAndJobsResultWritesTheSameFiles) {
  const std::string db = s_scratch->file("no-errors.db");
  const std::string from_design = s_scratch->file("no-errors-design"), from_result = s_scratch->file("no-errors-result");
  // A budget of a microsecond ends the design while it inflates the start: a completed job with no error.
  const ProcessResult designed = run({"--db", db, "design", bumpy(), "--material", "silicone", "--resolution", "0",
                                      "--max-time", "0.000001", "--out-dir", from_design, "--json"});
  ASSERT_EQ(designed.exit_code, 3) << designed.err;
  const auto lines = split_lines(designed.out);
  ASSERT_EQ(lines.size(), 1u) << designed.out;
  const std::string& json = lines[0];
  EXPECT_EQ(json_field(json, "stop_reason"), "\"time_limit\"") << json;
  EXPECT_EQ(json_field(json, "converged"), "false") << json;
  for (const char* key : {"avg_error_mm", "max_error_mm", "avg_error_rel", "max_error_rel", "baseline_avg_error_mm",
                          "baseline_max_error_mm"})
    EXPECT_EQ(json_field(json, key), "null") << key << " in " << json;
  EXPECT_FALSE(json_field(json, "resumed_from_iteration").has_value()) << "absent when the design ran through";

  const std::size_t at = designed.err.find("j-");
  ASSERT_NE(at, std::string::npos) << designed.err;
  const std::string id = designed.err.substr(at, 18);
  const ProcessResult result = run({"--db", db, "jobs", "result", id, "--out-dir", from_result});
  ASSERT_EQ(result.exit_code, 3) << result.err;
  EXPECT_EQ(read_text(from_result + "/report.json"), json + "\n");
  for (const auto& entry : std::filesystem::directory_iterator(from_design)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(read_text(from_result + "/" + name), read_text(entry.path().string())) << name;
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(from_result), std::filesystem::directory_iterator()),
            std::distance(std::filesystem::directory_iterator(from_design), std::filesystem::directory_iterator()));
}

}  // namespace
}  // namespace balloon::testing
