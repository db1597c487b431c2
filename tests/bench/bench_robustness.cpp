// Forward-solver robustness (issue 10, section 1): every corpus mesh in DATA_DIR/meshes, at two sizes
// (20 mm and 200 mm bounding-box diagonal), as given and downscaled by half (shrunk by 0.5 about its
// centroid, as a design start is), with silicone, latex, a Neo-Hookean rubber (mu = 0.3 MPa) and a
// Mooney-Rivlin one (C1 = 0.1397, C2 = 0.0280 MPa), each inflated under volume control to ratio 2 and 8
// (27 for latex), 0.5 mm thick. Meshes above
// --resolution * 1.25 vertices are remeshed to --resolution vertices with the design's target
// preparation (CGAL isotropic remeshing); smaller ones keep their slivers. Prints one line per case (with
// the case's peak memory, MB and MB per 1,000 vertices) and the number of failures: a case fails when the solver neither converges nor says why in physical terms
// (an equilibrium that passes through itself is such an answer: counted apart, not as a failure). --tension-field
// switches on Pipkin's relaxation (InflationOptions::tension_field, off by default).
// --bending on|off|auto sets InflationOptions::bending (auto by default: switched on when a volume step fails).
// --pressure-fraction F runs each case under pressure control instead, at F times the pressure its volume
// run reaches (that run first, untimed; a case without one is skipped): an answer above the balloon's
// maximum pressure is physical too ("max", counted apart).
// Usage: bench_robustness [DATA_DIR] [--mesh SUBSTRING]... [--material silicone|latex|neo-hookean|mooney-rivlin]
//                         [--resolution N=4000] [--max-time S=120] [--tension-field] [--bending on|off|auto]
//                         [--pressure-fraction F] [--quick] [--size MM] [--form given|half] [--ratio R]
//   --size, --form, --ratio: only the cases with this diagonal (mm), form or volume ratio (to rerun one case).
//   --quick: 200 mm as given, the largest ratio only (one case per mesh and material).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "design/target_preparation.hpp"
#include "material/material.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "peak_memory.hpp"
#include "solve/inflation.hpp"

namespace {

struct NamedMaterial {
  std::string label;
  balloon::Material material;
  std::vector<double> ratios;
};

struct Failure {
  std::string label;
  std::string message;
};

bool selected(const std::vector<std::string>& filters, const std::string& name) {
  if (filters.empty()) return true;
  return std::any_of(filters.begin(), filters.end(),
                     [&](const std::string& f) { return name.find(f) != std::string::npos; });
}

balloon::TriMesh shrunk_about_centroid(balloon::TriMesh mesh, double factor) {
  const Eigen::RowVector3d center = balloon::centroid(mesh.vertices);
  mesh.vertices = ((mesh.vertices.rowwise() - center) * factor).rowwise() + center;
  return mesh;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  std::string data_dir = BALLOON_TEST_DATA_DIR;
  std::vector<std::string> mesh_filters, material_filters;
  int resolution = 4000;
  double max_time_s = 120.0;
  bool quick = false;
  bool tension_field = false;
  double pressure_fraction = 0.0;  // > 0: each case under pressure control at this fraction of its volume run's pressure
  balloon::BendingUse bending = balloon::BendingUse::Auto;
  double only_size = 0.0, only_ratio = 0.0;  // 0: all
  std::string only_form;                     // empty: both
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--quick") quick = true;
    else if (arg == "--tension-field") tension_field = true;
    else if (arg == "--bending") {
      const std::string use = value();
      bending = use == "on" ? balloon::BendingUse::On : use == "off" ? balloon::BendingUse::Off : balloon::BendingUse::Auto;
    }
    else if (arg == "--mesh") mesh_filters.push_back(value());
    else if (arg == "--material") material_filters.push_back(value());
    else if (arg == "--resolution") resolution = std::atoi(value().c_str());
    else if (arg == "--max-time") max_time_s = std::atof(value().c_str());
    else if (arg == "--size") only_size = std::atof(value().c_str());
    else if (arg == "--ratio") only_ratio = std::atof(value().c_str());
    else if (arg == "--form") only_form = value();
    else if (arg == "--pressure-fraction") pressure_fraction = std::atof(value().c_str());
    else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr, "unknown option %s\n", arg.c_str());
      return 2;
    } else data_dir = arg;
  }

  std::vector<NamedMaterial> materials = {
      {"silicone", *balloon::parse_material_spec("silicone"), {2.0, 8.0}},
      {"latex", *balloon::parse_material_spec("latex"), {2.0, 27.0}},
      {"neo-hookean", *balloon::parse_material_spec("neo-hookean:mu=0.3"), {2.0, 8.0}},
      // Our Mooney-Rivlin fit to Meunier's equibiaxial silicone data (`balloon fit-material
      // tests/data/materials/meunier2008_silicone_et.csv --test equibiaxial --model mooney-rivlin`).
      {"mooney-rivlin", *balloon::parse_material_spec("mooney-rivlin:C1=0.139679,C2=0.0280028"), {2.0, 8.0}},
  };
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir + "/meshes")) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".off" || ext == ".obj") files.push_back(entry.path().filename().string());
  }
  std::sort(files.begin(), files.end());
  const std::vector<double> sizes = quick ? std::vector<double>{200.0} : std::vector<double>{20.0, 200.0};
  const std::vector<double> shrink_factors = quick ? std::vector<double>{1.0} : std::vector<double>{1.0, 0.5};

  if (pressure_fraction > 0.0)
    std::printf("pressure-controlled inflation at %g times the pressure the volume path reaches at each ratio "
                "(that run not timed or counted), ",
                pressure_fraction);
  else
    std::printf("volume-controlled inflation, ");
  std::printf("thickness 0.5 mm, remesh above %d vertices to %d, %g s per case\n", resolution * 5 / 4, resolution,
              max_time_s);
  std::printf("%-26s %6s %5s %6s %-12s %5s %-5s %4s %7s %7s %8s %8s %10s  %s\n", "mesh", "verts", "size", "form",
              "material", "ratio", "conv", "bend", "newton", "factors", "time_s", "peak_MB", "MB/1k_vert", "message");
  std::vector<Failure> failures;
  int passes_through_itself = 0;  // converged, but the surface intersects itself: "self" in the table
  int above_maximum = 0;          // pressure control above the balloon's maximum pressure: "max"
  std::vector<double> times;
  int cases = 0;
  for (const std::string& file : files) {
    if (!selected(mesh_filters, file)) continue;
    auto loaded = balloon::read_mesh(data_dir + "/meshes/" + file);
    if (!loaded) {
      failures.push_back({file, "cannot load: " + loaded.error()});
      std::printf("%-26s cannot load: %s\n", file.c_str(), loaded.error().c_str());
      continue;
    }
    if (auto check = balloon::validate_balloon_mesh(*loaded); !check) {
      failures.push_back({file, "invalid: " + check.error()});
      std::printf("%-26s invalid: %s\n", file.c_str(), check.error().c_str());
      continue;
    }
    for (double size : sizes) {
      if (only_size > 0.0 && size != only_size) continue;
      balloon::TriMesh mesh = *loaded;
      mesh.vertices *= size / balloon::bounding_box_diagonal(mesh.vertices);
      if (resolution > 0 && mesh.vertex_count() > resolution * 5 / 4) {
        balloon::TargetPreparationOptions prep;
        prep.resolution = resolution;
        prep.keep_vertex_tolerance = 0.0;
        auto prepared = balloon::prepare_target(mesh, prep);
        if (!prepared) {
          failures.push_back({file, "remeshing failed: " + prepared.error()});
          std::printf("%-26s remeshing failed: %s\n", file.c_str(), prepared.error().c_str());
          continue;
        }
        mesh = prepared->mesh;
      }
      for (double shrink : shrink_factors) {
        if (!only_form.empty() && only_form != (shrink == 1.0 ? "given" : "half")) continue;
        const balloon::TriMesh rest = shrink == 1.0 ? mesh : shrunk_about_centroid(mesh, shrink);
        for (const NamedMaterial& m : materials) {
          if (!selected(material_filters, m.label)) continue;
          std::vector<double> ratios = m.ratios;
          if (quick) ratios = {ratios.back()};
          for (double ratio : ratios) {
            if (only_ratio > 0.0 && ratio != only_ratio) continue;
            balloon::InflationOptions options;
            options.material = m.material;
            options.thickness_mm = 0.5;
            options.control = balloon::InflationControl::VolumeRatio;
            options.volume_ratio = ratio;
            options.max_time_s = max_time_s;
            options.tension_field = tension_field;
            options.bending = bending;
            if (pressure_fraction > 0.0) {
              // The reference: the pressure the volume path reaches at this ratio, which the pressure run's
              // path passes below it (a case whose volume run has no answer has no pressure case).
              const balloon::InflationResult reference = balloon::inflate(rest, options);
              if (!reference.converged) continue;
              options.control = balloon::InflationControl::Pressure;
              options.pressure_kpa = pressure_fraction * reference.pressure_kpa;
            }
            balloon::bench::reset_peak_memory();
            const balloon::InflationResult result = balloon::inflate(rest, options);
            const double peak_mb = balloon::bench::peak_memory_mb();
            ++cases;
            times.push_back(result.time_s);
            const char* form = shrink == 1.0 ? "given" : "half";
            const bool self = result.stop == balloon::InflationStop::PassesThroughItself;
            const bool above = result.stop == balloon::InflationStop::AboveMaximumPressure;
            const bool physical_answer = self || above;
            std::printf("%-26s %6d %5.0f %6s %-12s %5.0f %-5s %4s %7d %7d %8.2f %8.1f %10.2f  %s\n", file.c_str(),
                        rest.vertex_count(), size, form, m.label.c_str(), ratio,
                        result.converged ? "yes" : self ? "self" : above ? "max" : "NO", result.bending ? "on" : "off",
                        result.newton_iterations, result.factorizations, result.time_s, peak_mb,
                        1000.0 * peak_mb / rest.vertex_count(), result.converged ? "" : result.message.c_str());
            std::fflush(stdout);
            if (self) ++passes_through_itself;
            if (above) ++above_maximum;
            if (!result.converged && !physical_answer) {
              char label[256];
              std::snprintf(label, sizeof(label), "%s %g mm %s %s x%g", file.c_str(), size, form, m.label.c_str(),
                            ratio);
              failures.push_back({label, result.message});
            }
          }
        }
      }
    }
  }
  const double max_time = times.empty() ? 0.0 : *std::max_element(times.begin(), times.end());
  std::printf("\ncases %d, failures %zu, passes through itself %d, ", cases, failures.size(), passes_through_itself);
  if (pressure_fraction > 0.0) std::printf("above the maximum pressure %d, ", above_maximum);
  std::printf("time per case median %.2f s, max %.2f s\n", median(times), max_time);
  for (const Failure& f : failures) std::printf("FAILED %s: %s\n", f.label.c_str(), f.message.c_str());
  return failures.empty() ? 0 : 1;
}
