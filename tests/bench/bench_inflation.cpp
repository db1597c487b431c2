// Static-solve benchmark: icospheres of growing size and sample organic meshes inflated to volume ratio 8.
// Prints time, Newton iterations, factorizations and peak memory against vertex count, and the
// log-log slope of time over the icospheres. Usage: bench_inflation [DATA_DIR] [--quick]
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "design/target_preparation.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "solve/inflation.hpp"

namespace {

double peak_memory_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
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
  Row row{name, mesh.vertex_count(), balloon::inflate(mesh, options)};
  std::printf("%-28s %8d %9.3f %7d %8d %6d %10.3g %9.2f %9.1f  %s\n", name.c_str(), row.vertices, row.result.time_s,
              row.result.newton_iterations, row.result.factorizations, row.result.load_steps, row.result.residual_norm,
              row.result.pressure_kpa, peak_memory_mb(), row.result.converged ? "converged" : row.result.message.c_str());
  std::fflush(stdout);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = BALLOON_TEST_DATA_DIR;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") quick = true;
    else data_dir = arg;
  }
  auto material = balloon::parse_material_spec("silicone");
  std::printf("static solve to volume ratio 8, material %s, thickness 0.5 mm\n",
              balloon::material_spec(*material).c_str());
  std::printf("%-28s %8s %9s %7s %8s %6s %10s %9s %9s  %s\n", "mesh", "vertices", "time_s", "newton", "factors",
              "steps", "residual_N", "p_kPa", "peak_MB", "status");
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
  return 0;
}
