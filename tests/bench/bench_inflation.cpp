// Static-solve benchmark: icospheres of growing size and sample organic meshes inflated to volume ratio 8.
// Prints time, Newton iterations, factorizations and peak memory (MB, and MB per 1,000 vertices) against
// vertex count, and the log-log slope of time over the icospheres. Then, end to end (issue 14), the CLI
// `balloon simulate` of geodesic spheres of 362 and 100,002 vertices (silicone, x8) as separate processes
// with their own store: wall time against the solver's own time_s, and the process's peak memory.
// Usage: bench_inflation [DATA_DIR] [--quick] [--cli PATH_TO_BALLOON | --no-cli]
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "design/target_preparation.hpp"
#include "geodesic_sphere.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "peak_memory.hpp"
#include "solve/inflation.hpp"

namespace {

struct ProcessRun {
  int exit_code = -1;
  double wall_s = 0.0;
  double peak_mb = 0.0;
  std::string out;
};

/// Runs `args` (args[0] the program) with stdout captured; wall time and the child's peak memory.
ProcessRun run_process(const std::vector<std::string>& args, const std::string& stdout_path) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  ProcessRun run;
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0) {
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  }
  posix_spawn_file_actions_destroy(&actions);
  std::ifstream in(stdout_path);
  std::ostringstream text;
  text << in.rdbuf();
  run.out = text.str();
  return run;
}

/// The number after "key": in a JSON text; NaN when absent.
double json_number(const std::string& json, const std::string& key) {
  const std::size_t at = json.find("\"" + key + "\":");
  return at == std::string::npos ? std::nan("") : std::atof(json.c_str() + at + key.size() + 3);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

/// `balloon simulate` end to end, the CLI and its embedded service in one process, as a user runs it.
void end_to_end(const std::string& cli, bool quick) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("balloon-bench-e2e-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string db = (dir / "balloon.db").string();
  const std::string captured = (dir / "stdout.txt").string();
  std::printf("\nend to end: %s simulate SPHERE --material silicone --volume-ratio 8 --out OUT.obj --json\n", cli.c_str());
  std::printf("(a fresh store in %s; issue 14 'now': 303 vertices 0.11 s; 100,002 vertices solver 8.8 s, 23.7 s wall, 817 MB)\n",
              dir.c_str());
  std::vector<double> start_s;
  for (int i = 0; i < 5; ++i) start_s.push_back(run_process({cli, "--help"}, captured).wall_s);
  std::printf("process start and exit alone (balloon --help, median of 5): %.3f s\n", median(start_s));
  std::printf("%-26s %8s %9s %9s %9s %8s %9s %10s\n", "mesh", "vertices", "solver_s", "wall_s", "outside_s",
              "wall/sol", "peak_MB", "MB/1k_vert");
  std::vector<int> frequencies = {6};
  if (!quick) frequencies.push_back(100);
  for (const int n : frequencies) {
    const balloon::TriMesh sphere = balloon::bench::geodesic_sphere(50.0, n);
    const std::string mesh_path = (dir / ("sphere" + std::to_string(sphere.vertex_count()) + ".obj")).string();
    if (auto written = balloon::write_mesh(sphere, mesh_path); !written) {
      std::printf("cannot write %s: %s\n", mesh_path.c_str(), written.error().c_str());
      continue;
    }
    const int repeats = n <= 10 ? 5 : 1;
    std::vector<double> wall, solver, peak;
    for (int r = 0; r < repeats; ++r) {
      const ProcessRun run = run_process({cli, "--db", db, "simulate", mesh_path, "--material", "silicone",
                                          "--volume-ratio", "8", "--out", (dir / "out.obj").string(), "--json"},
                                         captured);
      if (run.exit_code != 0) {
        std::printf("%-26s exit code %d\n", mesh_path.c_str(), run.exit_code);
        break;
      }
      wall.push_back(run.wall_s);
      solver.push_back(json_number(run.out, "time_s"));
      peak.push_back(run.peak_mb);
    }
    if (wall.empty()) continue;
    const double w = median(wall), t = median(solver), m = median(peak);
    char name[64];
    std::snprintf(name, sizeof(name), "geodesic sphere n=%d", n);
    std::printf("%-26s %8d %9.3f %9.3f %9.3f %8.2f %9.1f %10.2f\n", name, sphere.vertex_count(), t, w, w - t, w / t, m,
                m / (sphere.vertex_count() / 1000.0));
    std::fflush(stdout);
  }
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

struct Row {
  std::string name;
  int vertices;
  balloon::InflationResult result;
};

Row run(const std::string& name, const balloon::TriMesh& mesh, const balloon::Material& material) {
  balloon::InflationOptions options;
  options.material = material;
  options.thickness_mm = 0.5;
  options.control = balloon::InflationControl::VolumeRatio;
  options.volume_ratio = 8.0;
  options.max_time_s = 300;
  balloon::bench::reset_peak_memory();
  Row row{name, mesh.vertex_count(), balloon::inflate(mesh, options)};
  const double peak_mb = balloon::bench::peak_memory_mb();
  std::printf("%-28s %8d %9.3f %7d %8d %6d %10.3g %9.2f %9.1f %10.2f  %s\n", name.c_str(), row.vertices,
              row.result.time_s, row.result.newton_iterations, row.result.factorizations, row.result.load_steps,
              row.result.residual_norm, row.result.pressure_kpa, peak_mb, peak_mb / (row.vertices / 1000.0),
              row.result.converged ? "converged" : row.result.message.c_str());
  std::fflush(stdout);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = BALLOON_TEST_DATA_DIR;
  std::string cli = BALLOON_CLI_PATH;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") quick = true;
    else if (arg == "--no-cli") cli.clear();
    else if (arg == "--cli" && i + 1 < argc) cli = argv[++i];
    else data_dir = arg;
  }
  auto material = balloon::parse_material_spec("silicone");
  std::printf("static solve to volume ratio 8, material %s, thickness 0.5 mm\n",
              balloon::material_spec(*material).c_str());
  std::printf("%-28s %8s %9s %7s %8s %6s %10s %9s %9s %10s  %s\n", "mesh", "vertices", "time_s", "newton", "factors",
              "steps", "residual_N", "p_kPa", "peak_MB", "MB/1k_vert", "status");
  std::vector<Row> spheres;
  const int largest = quick ? 4 : 6;
  for (int k = 3; k <= largest; ++k)
    spheres.push_back(run("icosphere r=50mm sub " + std::to_string(k), balloon::make_icosphere(50.0, k), *material));
  {
    // The 5k-vertex target size: an icosphere remeshed isotropically to about 5,000 vertices.
    balloon::TargetPreparationOptions prep;
    prep.resolution = 5000;
    prep.keep_vertex_tolerance = 0.0;
    auto sphere5k = balloon::prepare_target(balloon::make_icosphere(50.0, 5), prep);
    if (sphere5k) run("remeshed sphere r=50mm", sphere5k->mesh, *material);
  }
  if (spheres.size() >= 2) {
    const auto& a = spheres.front();
    const auto& b = spheres.back();
    const double slope = std::log(b.result.time_s / a.result.time_s) / std::log(double(b.vertices) / a.vertices);
    std::printf("log-log slope of time against vertices (icospheres %d..%d): %.2f\n", a.vertices, b.vertices, slope);
  }
  const std::vector<std::string> samples = quick ? std::vector<std::string>{"stanford_bunny_1839.obj"}
                                                 : std::vector<std::string>{"stanford_bunny_1839.obj", "spot.obj",
                                                                            "retinal_bumpy_blob.off", "hand_fist.off",
                                                                            "cube_866.off"};
  for (const auto& file : samples) {
    auto mesh = balloon::read_mesh(data_dir + "/meshes/" + file);
    if (!mesh) {
      std::printf("%-28s cannot load: %s\n", file.c_str(), mesh.error().c_str());
      continue;
    }
    if (auto check = balloon::validate_balloon_mesh(*mesh); !check) {
      std::printf("%-28s invalid: %s\n", file.c_str(), check.error().c_str());
      continue;
    }
    // Sample meshes have no unit: scale to a 100 mm bounding-box diagonal.
    const double scale = 100.0 / balloon::bounding_box_diagonal(mesh->vertices);
    mesh->vertices *= scale;
    run(file + " (100 mm)", *mesh, *material);
  }
  if (!cli.empty()) end_to_end(cli, quick);
  return 0;
}
