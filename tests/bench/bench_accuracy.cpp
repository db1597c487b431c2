// Error against run time across resolutions (issue 14). Silicone, 0.5 mm, volume ratio 8 throughout.
// Forward part:
//  - geodesic spheres (radius 50 mm) of about 500 to 40,000 vertices: the relative error of the pressure
//    against the closed form of a thin sphere at the stretch of the reached volume, for the 50 mm sphere
//    the mesh approximates and for the polyhedron's own radius 3V/A (the ctest's convention);
//  - one organic corpus shape (spot by default) at a 150 mm bounding-box diagonal, remeshed to 500 to
//    16,000 vertices: the mean distance of its inflated surface to the inflated 40,000-vertex remesh (after
//    a rigid point-to-surface alignment; two-sided: each surface's vertices to the other, averaged), in mm
//    and in % of that reference's diagonal; beside it the same distance for the rest meshes (what the
//    remeshing alone costs).
//  Per row: vertices, the solver's time_s, Newton iterations, factorizations, the error, peak memory (MB)
//  and MB per 1,000 vertices.
// Design part: three corpus shapes (spot, bunny, blob; 150 mm diagonal), adjoint method, each remeshed to
//  1,000 to 16,000 vertices and designed within --max-time: the average error (% of the target's diagonal,
//  as the design reports it against its own target) against time of each run, the Pareto front over all
//  (time, error) points of a shape, and the time each resolution took to reach a few error levels.
// Writes forward_sphere.csv, forward_organic.csv, design_runs.csv, design_curves.csv,
// forward_error_vs_time.svg and design_error_vs_time.svg into --out.
// Usage: bench_accuracy [--part forward|design|both] [--mesh NAME]... [--max-time S=60]
//                       [--max-iterations N=1000000] [--resolutions N,N,...] [--out DIR=bench-accuracy-out]
//                       [--data DIR] [--quick]
//   --max-time: each design's budget (s); --max-iterations: each design's iteration limit (default: in
//            effect none, so the budget ends every design that does not converge or stall first).
//   --mesh: keep the corpus shapes whose file name contains NAME (the forward part uses the first one kept).
//   --resolutions: the design part's vertex counts (default 1000,2000,4000,8000,16000).
//   --quick: spheres of 492-1,962 vertices, the organic shape at 500 and 1,000 against a 4,000 reference,
//            one design shape at 1,000 and 2,000 vertices, 10 s each.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "design/balloon_design.hpp"
#include "design/surface_distance.hpp"
#include "design/target_preparation.hpp"
#include "geodesic_sphere.hpp"
#include "material/material.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "peak_memory.hpp"
#include "solve/inflation.hpp"
#include "svg_plot.hpp"

namespace {

using balloon::bench::PlotPanel;
using balloon::bench::PlotSeries;

constexpr double THICKNESS_MM = 0.5;
constexpr double VOLUME_RATIO = 8.0;
constexpr double SIZE_MM = 150.0;          // corpus shapes' bounding-box diagonal (mm)
constexpr double SPHERE_RADIUS_MM = 50.0;

struct Settings {
  bool forward = true, design = true, quick = false;
  double max_time_s = 60.0;
  int max_iterations = 1000000;  // in effect none: the time budget ends each design (DesignOptions: 200)
  std::vector<int> resolutions = {1000, 2000, 4000, 8000, 16000};
  std::vector<std::string> mesh_filters;
  std::string out_dir = "bench-accuracy-out";
  std::string data_dir = BALLOON_TEST_DATA_DIR;
};

struct Shape {
  std::string name;
  std::string file;
};

// A value not computed is NaN here (plain doubles: GCC 12 warns of std::optional's payload at -O3) and
// prints as "n/a", never 0.
constexpr double NOT_COMPUTED = std::numeric_limits<double>::quiet_NaN();

/// A value as text, or "n/a" when it was not computed.
std::string cell(double value, const char* format = "%.3g") {
  if (!std::isfinite(value)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

/// 100 * value / base, or NOT_COMPUTED without a value.
double percent(const std::optional<double>& value, double base) { return value ? 100.0 * *value / base : NOT_COMPUTED; }

std::string thousands(int n) {
  char buffer[32];
  if (n >= 1000) std::snprintf(buffer, sizeof(buffer), "%d,%03d", n / 1000, n % 1000);
  else std::snprintf(buffer, sizeof(buffer), "%d", n);
  return buffer;
}

/// Closed-form pressure (kPa) of a thin incompressible sphere of rest radius R (mm) and thickness h (mm)
/// at equibiaxial stretch l: energy 4 pi R^2 h Psi(l) against p 4/3 pi R^3 l^3 (as in
/// tests/core/solve/test_inflation.cpp).
double sphere_pressure_kpa(const balloon::Material& material, double h, double R, double l) {
  const double I1 = 2 * l * l + std::pow(l, -4), I2 = std::pow(l, 4) + 2 * std::pow(l, -2);
  const double dI1 = 4 * l - 4 * std::pow(l, -5), dI2 = 4 * std::pow(l, 3) - 4 * std::pow(l, -3);
  const balloon::InvariantDerivatives d = balloon::strain_energy(material, I1, I2);
  return 1e3 * h * (d.d1 * dI1 + d.d2 * dI2) / (R * l * l);
}

/// One static solve to volume ratio 8 with its own peak memory.
struct Solve {
  balloon::InflationResult result;
  double peak_mb = 0.0;
};

Solve solve(const balloon::TriMesh& rest, const balloon::Material& material) {
  balloon::InflationOptions options;
  options.material = material;
  options.thickness_mm = THICKNESS_MM;
  options.control = balloon::InflationControl::VolumeRatio;
  options.volume_ratio = VOLUME_RATIO;
  options.max_time_s = 900;
  balloon::bench::reset_peak_memory();
  Solve s{balloon::inflate(rest, options), 0.0};
  s.peak_mb = balloon::bench::peak_memory_mb();
  return s;
}

std::string status(const balloon::InflationResult& result) {
  return result.converged ? "converged" : std::string(balloon::inflation_stop_word(result.stop)) + ": " + result.message;
}

/// `points` moved rigidly onto `surface` (iterated closest points: align to the closest surface points,
/// repeat until the motion is below 1e-9 of the diagonal). Two inflations of different meshes of one shape
/// sit in slightly different rigid placements (the six pinned coordinates differ); this takes that away.
balloon::Positions align_to_surface(balloon::Positions points, const balloon::SurfaceDistance& surface) {
  const double tolerance = 1e-9 * surface.bbox_diagonal_mm();
  for (int iteration = 0; iteration < 50; ++iteration) {
    balloon::Positions closest;
    surface.closest_points(points, closest);
    const balloon::RigidTransform motion = balloon::rigid_alignment(points, closest);
    const balloon::Positions moved = motion.apply(points);
    const double change = (moved - points).rowwise().norm().maxCoeff();
    points = moved;
    if (change < tolerance) break;
  }
  return points;
}

/// The corpus shape scaled to SIZE_MM and remeshed to about `resolution` vertices.
balloon::Result<balloon::PreparedTarget> prepare(const balloon::TriMesh& input, int resolution) {
  balloon::TargetPreparationOptions prep;
  prep.size_mm = SIZE_MM;
  prep.resolution = resolution;
  prep.keep_vertex_tolerance = 0.0;  // every row remeshed the same way, the input's own mesh never kept
  return balloon::prepare_target(input, prep);
}

balloon::Result<balloon::TriMesh> load(const Settings& settings, const Shape& shape) {
  return balloon::read_mesh(settings.data_dir + "/meshes/" + shape.file);
}

/// An empty series drawn with markers: solid with dots, or dashed with rings.
PlotSeries series(const std::string& label, const std::string& color, bool dashed) {
  PlotSeries s;
  s.label = label;
  s.color = color;
  s.dashed = dashed;
  s.marker_radius = 3.5;
  s.hollow = dashed;
  return s;
}

// ---------------------------------------------------------------------------------------------- forward

PlotPanel sphere_part(const Settings& settings, const balloon::Material& material) {
  const std::vector<int> frequencies = settings.quick ? std::vector<int>{7, 10, 14} : std::vector<int>{7, 10, 14, 20, 28, 40, 64};
  std::printf("\n(a) geodesic spheres, radius %.0f mm: pressure against the closed form at the reached stretch\n",
              SPHERE_RADIUS_MM);
  std::printf("%8s %9s %7s %8s %10s %12s %10s %12s %14s %9s %10s  %s\n", "vertices", "time_s", "newton", "factors",
              "p_kPa", "p_exact_kPa", "p_err_%", "R_3V/A_mm", "p_err_3V/A_%", "peak_MB", "MB/1k_vert", "status");
  std::ofstream csv(settings.out_dir + "/forward_sphere.csv");
  csv << "vertices,time_s,newton_iterations,factorizations,pressure_kpa,exact_pressure_kpa,pressure_error_pct,"
         "polyhedron_radius_mm,pressure_error_polyhedron_pct,peak_mb,mb_per_1k_vertices,converged\n";
  PlotSeries sphere = series("vs the 50 mm sphere", balloon::bench::palette_color(0), false);
  PlotSeries polyhedron = series("vs radius 3V/A (ctest)", balloon::bench::palette_color(1), true);
  for (const int n : frequencies) {
    const balloon::TriMesh mesh = balloon::bench::geodesic_sphere(SPHERE_RADIUS_MM, n);
    const Solve s = solve(mesh, material);
    const balloon::InflationResult& r = s.result;
    const int vertices = mesh.vertex_count();
    // The polyhedron's own radius: the sphere with its volume-to-area ratio.
    const double radius_3v_a = 3.0 * balloon::enclosed_volume(mesh.vertices, mesh.faces) /
                               balloon::surface_area(mesh.vertices, mesh.faces);
    double exact = NOT_COMPUTED, error_pct = NOT_COMPUTED, error_poly_pct = NOT_COMPUTED, pressure = NOT_COMPUTED;
    if (r.converged) {
      const double stretch = std::cbrt(r.volume_ratio);
      pressure = r.pressure_kpa;
      exact = sphere_pressure_kpa(material, THICKNESS_MM, SPHERE_RADIUS_MM, stretch);
      error_pct = 100.0 * std::abs(pressure - exact) / exact;
      const double exact_poly = sphere_pressure_kpa(material, THICKNESS_MM, radius_3v_a, stretch);
      error_poly_pct = 100.0 * std::abs(pressure - exact_poly) / exact_poly;
      sphere.points.push_back({r.time_s, error_pct});
      polyhedron.points.push_back({r.time_s, error_poly_pct});
      sphere.point_labels.push_back(thousands(vertices));
    }
    const double per_1k = s.peak_mb / (vertices / 1000.0);
    std::printf("%8d %9.3f %7d %8d %10s %12s %10s %12.4f %14s %9.1f %10.2f  %s\n", vertices, r.time_s,
                r.newton_iterations, r.factorizations, cell(pressure, "%.4f").c_str(), cell(exact, "%.4f").c_str(),
                cell(error_pct, "%.3g").c_str(), radius_3v_a, cell(error_poly_pct, "%.3g").c_str(), s.peak_mb, per_1k,
                status(r).c_str());
    std::fflush(stdout);
    csv << vertices << "," << r.time_s << "," << r.newton_iterations << "," << r.factorizations << ","
        << cell(pressure, "%.6g") << "," << cell(exact, "%.6g") << "," << cell(error_pct, "%.6g") << "," << radius_3v_a
        << "," << cell(error_poly_pct, "%.6g") << "," << s.peak_mb << "," << per_1k << ","
        << (r.converged ? "true" : "false") << "\n";
  }
  PlotPanel panel;
  panel.title = "Sphere (r = 50 mm): pressure error";
  panel.x = {"solve time (s)", true};
  panel.y = {"relative pressure error (%)", true};
  panel.series = {sphere, polyhedron};
  return panel;
}

/// Mean distance between two surfaces (mm): the average of the mean distance of a's vertices to b and of
/// b's vertices to a. Both directions, so that the chords between one mesh's vertices count too.
double two_sided_mean_mm(const balloon::TriMesh& a, const balloon::SurfaceDistance& b_surface,
                         const balloon::TriMesh& b) {
  return 0.5 * (b_surface.stats(a.vertices).avg_mm + balloon::SurfaceDistance(a).stats(b.vertices).avg_mm);
}

PlotPanel organic_part(const Settings& settings, const balloon::Material& material, const Shape& shape) {
  const std::vector<int> resolutions = settings.quick ? std::vector<int>{500, 1000}
                                                      : std::vector<int>{500, 1000, 2000, 4000, 8000, 16000};
  const int reference_resolution = settings.quick ? 4000 : 40000;
  PlotPanel panel;
  panel.title = shape.name + " (" + std::to_string(static_cast<int>(SIZE_MM)) + " mm): distance to the " +
                thousands(reference_resolution) + "-vertex solution";
  panel.x = {"solve time (s)", true};
  panel.y = {"mean distance (% of inflated diagonal)", true};
  std::printf("\n(b) %s at a %.0f mm diagonal, remeshed; reference: the %d-vertex remesh inflated\n", shape.file.c_str(),
              SIZE_MM, reference_resolution);
  const auto input = load(settings, shape);
  if (!input) {
    std::printf("cannot load %s: %s\n", shape.file.c_str(), input.error().c_str());
    return panel;
  }
  // The coarse solves first, the reference last, so that no row's peak memory holds the reference.
  struct Run {
    balloon::TriMesh rest;
    Solve solve;
  };
  std::vector<Run> runs;
  for (const int resolution : resolutions) {
    auto target = prepare(*input, resolution);
    if (!target) {
      std::printf("%8d cannot prepare: %s\n", resolution, target.error().c_str());
      continue;
    }
    Solve s = solve(target->mesh, material);
    runs.push_back({std::move(target->mesh), std::move(s)});
  }
  auto reference = prepare(*input, reference_resolution);
  if (!reference) {
    std::printf("cannot prepare the reference: %s\n", reference.error().c_str());
    return panel;
  }
  const balloon::TriMesh& reference_rest = reference->mesh;
  runs.push_back({reference_rest, solve(reference_rest, material)});
  const balloon::InflationResult& reference_result = runs.back().solve.result;
  const balloon::TriMesh reference_inflated{reference_result.deformed, reference_rest.faces};
  std::optional<balloon::SurfaceDistance> inflated_reference;
  if (reference_result.converged) inflated_reference.emplace(reference_inflated);
  const balloon::SurfaceDistance rest_reference(reference_rest);
  const double diag = inflated_reference ? inflated_reference->bbox_diagonal_mm() : NOT_COMPUTED;
  std::printf("reference inflated: %s, diagonal %s mm (rest %.1f mm)\n", status(reference_result).c_str(),
              cell(diag, "%.1f").c_str(), reference->bbox_diag_mm);
  std::printf("(err: two-sided mean distance between the inflated surfaces after a rigid alignment; node_err: this "
              "mesh's inflated vertices to the reference alone; rest_err: two-sided, the rest meshes)\n");
  std::printf("%8s %9s %7s %8s %10s %10s %11s %12s %9s %10s  %s\n", "vertices", "time_s", "newton", "factors", "err_mm",
              "err_%diag", "node_err_mm", "rest_err_mm", "peak_MB", "MB/1k_vert", "status");
  std::ofstream csv(settings.out_dir + "/forward_organic.csv");
  csv << "shape,vertices,time_s,newton_iterations,factorizations,mean_distance_mm,mean_distance_pct_diagonal,"
         "node_distance_mm,rest_mean_distance_mm,peak_mb,mb_per_1k_vertices,converged\n";
  PlotSeries inflated = series("inflated vs reference", balloon::bench::palette_color(2), false);
  PlotSeries rest = series("rest meshes (remeshing)", balloon::bench::palette_color(7), true);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run& run = runs[i];
    const balloon::InflationResult& r = run.solve.result;
    const int vertices = run.rest.vertex_count();
    const bool is_reference = i + 1 == runs.size();  // no error: it is what the others are measured against
    double error_mm = NOT_COMPUTED, node_mm = NOT_COMPUTED, rest_mm = NOT_COMPUTED;
    if (!is_reference) {
      rest_mm = two_sided_mean_mm(run.rest, rest_reference, reference_rest);
      if (r.converged && inflated_reference) {
        const balloon::TriMesh aligned{align_to_surface(r.deformed, *inflated_reference), run.rest.faces};
        node_mm = inflated_reference->stats(aligned.vertices).avg_mm;
        error_mm = two_sided_mean_mm(aligned, *inflated_reference, reference_inflated);
      }
    }
    const double error_pct = 100.0 * error_mm / diag;  // NaN (n/a) when either is
    const double per_1k = run.solve.peak_mb / (vertices / 1000.0);
    std::printf("%8d %9.3f %7d %8d %10s %10s %11s %12s %9.1f %10.2f  %s\n", vertices, r.time_s, r.newton_iterations,
                r.factorizations, cell(error_mm, "%.4f").c_str(), cell(error_pct, "%.4f").c_str(),
                cell(node_mm, "%.4f").c_str(), cell(rest_mm, "%.4f").c_str(), run.solve.peak_mb, per_1k,
                status(r).c_str());
    std::fflush(stdout);
    csv << shape.name << "," << vertices << "," << r.time_s << "," << r.newton_iterations << "," << r.factorizations
        << "," << cell(error_mm, "%.6g") << "," << cell(error_pct, "%.6g") << "," << cell(node_mm, "%.6g") << ","
        << cell(rest_mm, "%.6g") << "," << run.solve.peak_mb << "," << per_1k << "," << (r.converged ? "true" : "false")
        << "\n";
    if (std::isfinite(error_pct)) {
      inflated.points.push_back({r.time_s, error_pct});
      inflated.point_labels.push_back(thousands(vertices));
      rest.points.push_back({r.time_s, 100.0 * rest_mm / diag});
    }
  }
  panel.series = {inflated, rest};
  return panel;
}

void forward_part(const Settings& settings, const balloon::Material& material, const std::vector<Shape>& shapes) {
  std::printf("\nforward solve to volume ratio %g, %s, thickness %g mm\n", VOLUME_RATIO,
              balloon::material_spec(material).c_str(), THICKNESS_MM);
  std::vector<PlotPanel> panels = {sphere_part(settings, material)};
  if (!shapes.empty()) panels.push_back(organic_part(settings, material, shapes.front()));
  std::ofstream(settings.out_dir + "/forward_error_vs_time.svg")
      << balloon::bench::svg_figure("Forward solve: error against solve time (silicone, 0.5 mm, volume ratio 8)", panels,
                                    2, "labels: vertex counts; time: the solver's own time_s on the machine of the run");
}

// ----------------------------------------------------------------------------------------------- design

struct CurvePoint {
  double time_s = 0.0;
  double error_pct = 0.0;
  int vertices = 0;
  bool pareto = false;
};

/// Marks the points no other point beats in both time and error (ties in time: the smaller error).
void mark_pareto(std::vector<CurvePoint*>& points) {
  std::sort(points.begin(), points.end(), [](const CurvePoint* a, const CurvePoint* b) {
    return a->time_s != b->time_s ? a->time_s < b->time_s : a->error_pct < b->error_pct;
  });
  double best = std::numeric_limits<double>::infinity();
  for (CurvePoint* p : points)
    if (p->error_pct < best) {
      p->pareto = true;
      best = p->error_pct;
    }
}

PlotPanel design_shape(const Settings& settings, const balloon::Material& material, const Shape& shape,
                       const std::vector<int>& resolutions, std::ofstream& runs_csv, std::ofstream& curves_csv,
                       std::string& levels_table) {
  PlotPanel panel;
  panel.title = shape.name + " (" + std::to_string(static_cast<int>(SIZE_MM)) + " mm, adjoint)";
  panel.x = {"design time (s)", true};
  panel.y = {"avg error (% of diagonal)", true};
  const auto input = load(settings, shape);
  if (!input) {
    std::printf("%-8s cannot load %s: %s\n", shape.name.c_str(), shape.file.c_str(), input.error().c_str());
    return panel;
  }
  std::vector<balloon::PreparedTarget> targets;
  for (const int resolution : resolutions) {
    auto target = prepare(*input, resolution);
    if (!target) {
      std::printf("%-8s %8d cannot prepare: %s\n", shape.name.c_str(), resolution, target.error().c_str());
      continue;
    }
    targets.push_back(std::move(*target));
  }
  if (targets.empty()) return panel;
  std::vector<std::vector<CurvePoint>> curves;
  std::vector<int> vertex_counts;
  for (const balloon::PreparedTarget& target : targets) {
    const int vertices = target.mesh.vertex_count();
    // The input mesh's vertices (scaled as the target was) to the remeshed target's surface: how far the
    // target itself is from the shape; the design is measured against its own target, without this.
    const double chord_pct =
        100.0 * balloon::SurfaceDistance(target.mesh).stats(input->vertices * target.scale_factor).avg_rel;
    balloon::DesignOptions options;
    options.material = material;
    options.thickness_mm = THICKNESS_MM;
    options.volume_ratio = VOLUME_RATIO;
    options.method = balloon::DesignMethod::Adjoint;
    options.max_time_s = settings.max_time_s;
    options.max_iterations = settings.max_iterations;
    balloon::bench::reset_peak_memory();
    const balloon::DesignResult r = balloon::design_balloon(target.mesh, options);
    const double peak_mb = balloon::bench::peak_memory_mb();
    const double diag = std::max(r.bbox_diag_mm, 1e-12);
    std::vector<CurvePoint> curve;
    for (const balloon::ConvergenceSample& sample : r.log)
      curve.push_back({sample.time_s, 100.0 * sample.avg_error_mm / diag, vertices, false});
    const double start_pct = percent(r.baseline_avg_error_mm, diag);
    const double start_s = curve.empty() ? NOT_COMPUTED : curve.front().time_s;
    const double final_pct = percent(r.avg_error_rel, 1.0);
    const double max_pct = percent(r.max_error_rel, 1.0);
    const double per_1k = peak_mb / (vertices / 1000.0);
    std::printf("%-8s %8d %8.2f %6d %9s %11s %11s %11s %11.4f %9.1f %10.2f  %s\n", shape.name.c_str(), vertices, r.time_s,
                r.iterations, cell(start_s, "%.2f").c_str(), cell(start_pct, "%.4f").c_str(),
                cell(final_pct, "%.4f").c_str(), cell(max_pct, "%.4f").c_str(), chord_pct, peak_mb, per_1k,
                balloon::design_stop_name(r.stop).c_str());
    std::fflush(stdout);
    runs_csv << shape.name << "," << vertices << "," << r.time_s << "," << r.iterations << "," << cell(start_s, "%.6g")
             << "," << cell(start_pct, "%.6g") << "," << cell(final_pct, "%.6g") << "," << cell(max_pct, "%.6g") << ","
             << chord_pct << "," << peak_mb << "," << per_1k << "," << balloon::design_stop_name(r.stop) << "\n";
    curves.push_back(std::move(curve));
    vertex_counts.push_back(vertices);
  }
  std::vector<CurvePoint*> all;
  for (auto& curve : curves)
    for (CurvePoint& p : curve) all.push_back(&p);
  mark_pareto(all);  // sorts `all` by time
  // The front as a wide pale band under the curves, rings where it passes to another resolution.
  PlotSeries front;
  front.label = "Pareto front (all runs)";
  front.color = "#000000";
  front.line_width = 9.0;
  front.opacity = 0.2;
  PlotSeries switches;
  switches.label = "front changes resolution";
  switches.color = "#000000";
  switches.line = false;
  switches.marker_radius = 5.0;
  switches.hollow = true;
  int front_vertices = -1;
  for (const CurvePoint* p : all) {
    if (!p->pareto) continue;
    front.points.push_back({p->time_s, p->error_pct});
    if (p->vertices != front_vertices) switches.points.push_back({p->time_s, p->error_pct});
    front_vertices = p->vertices;
  }
  // Per resolution: how many front points, over which times and errors (the curves may interleave).
  std::printf("%-8s Pareto front:", shape.name.c_str());
  for (const int vertices : vertex_counts) {
    std::vector<const CurvePoint*> mine;
    for (const CurvePoint* p : all)
      if (p->pareto && p->vertices == vertices) mine.push_back(p);
    if (mine.empty()) std::printf("  %s: none;", thousands(vertices).c_str());
    else
      std::printf("  %s: %zu points, %.1f-%.1f s, %.3g%%-%.3g%%;", thousands(vertices).c_str(), mine.size(),
                  mine.front()->time_s, mine.back()->time_s, mine.front()->error_pct, mine.back()->error_pct);
  }
  std::printf("\n");
  panel.series.push_back(front);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    PlotSeries s;
    s.label = thousands(vertex_counts[i]) + " vertices";
    s.color = balloon::bench::palette_color(i);
    s.marker_radius = 2.0;
    for (const CurvePoint& p : curves[i]) {
      s.points.push_back({p.time_s, p.error_pct});
      curves_csv << shape.name << "," << p.vertices << "," << p.time_s << "," << p.error_pct << ","
                 << (p.pareto ? 1 : 0) << "\n";
    }
    panel.series.push_back(s);
  }
  panel.series.push_back(switches);
  // Time to reach each error level, per resolution ("-": not within the budget).
  const std::vector<double> levels = {3.0, 2.0, 1.0, 0.7, 0.5, 0.3};
  for (std::size_t i = 0; i < curves.size(); ++i) {
    std::string line = "| " + shape.name + " | " + thousands(vertex_counts[i]) + " |";
    for (const double level : levels) {
      const auto reached = std::find_if(curves[i].begin(), curves[i].end(),
                                        [&](const CurvePoint& p) { return p.error_pct <= level; });
      char buffer[32];
      if (reached == curves[i].end()) std::snprintf(buffer, sizeof(buffer), " - |");
      else std::snprintf(buffer, sizeof(buffer), " %.1f s |", reached->time_s);
      line += buffer;
    }
    levels_table += line + "\n";
  }
  return panel;
}

void design_part(const Settings& settings, const balloon::Material& material, const std::vector<Shape>& shapes) {
  std::vector<int> resolutions = settings.resolutions;
  std::sort(resolutions.begin(), resolutions.end());
  std::printf("\ninverse design (adjoint), %s, thickness %g mm, volume ratio %g, %.0f mm diagonal, budget %.0f s and %d "
              "iterations per design\n",
              balloon::material_spec(material).c_str(), THICKNESS_MM, VOLUME_RATIO, SIZE_MM, settings.max_time_s,
              settings.max_iterations);
  std::printf("(errors in %% of the target's bbox diagonal, each design against its own remeshed target; tgt_err: the "
              "input mesh's vertices to this target)\n");
  std::printf("%-8s %8s %8s %6s %9s %11s %11s %11s %11s %9s %10s  %s\n", "shape", "vertices", "time_s", "iters",
              "start_s", "start_err_%", "avg_err_%", "max_err_%", "tgt_err_%", "peak_MB", "MB/1k_vert", "stop");
  std::ofstream runs_csv(settings.out_dir + "/design_runs.csv");
  runs_csv << "shape,vertices,time_s,iterations,start_time_s,start_error_pct,avg_error_pct,max_error_pct,"
              "target_vs_input_pct,peak_mb,mb_per_1k_vertices,stop\n";
  std::ofstream curves_csv(settings.out_dir + "/design_curves.csv");
  curves_csv << "shape,vertices,time_s,avg_error_pct,pareto\n";
  std::string levels_table =
      "| shape | vertices | <= 3% | <= 2% | <= 1% | <= 0.7% | <= 0.5% | <= 0.3% |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
  std::vector<PlotPanel> panels;
  for (const Shape& shape : shapes)
    panels.push_back(design_shape(settings, material, shape, resolutions, runs_csv, curves_csv, levels_table));
  std::printf("\ntime (s) to reach an average error (%% of the diagonal), per resolution; '-': not within %.0f s\n%s",
              settings.max_time_s, levels_table.c_str());
  std::ofstream(settings.out_dir + "/design_levels.md") << levels_table;
  char note[160];
  std::snprintf(note, sizeof(note),
                "each curve: one design's error log; budget %.0f s per design; error against its own remeshed target",
                settings.max_time_s);
  std::ofstream(settings.out_dir + "/design_error_vs_time.svg")
      << balloon::bench::svg_figure("Design: average error against time per resolution (silicone, 0.5 mm, volume ratio 8)",
                                    panels, 3, note);
}

std::vector<int> parse_list(const std::string& text) {
  std::vector<int> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (const int v = std::atoi(item.c_str()); v > 0) values.push_back(v);
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  bool max_time_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--quick") {
      settings.quick = true;
    } else if (arg == "--part" && has_value) {
      const std::string part = argv[++i];
      settings.forward = part == "forward" || part == "both";
      settings.design = part == "design" || part == "both";
      if (!settings.forward && !settings.design) {
        std::fprintf(stderr, "bench_accuracy: --part must be forward, design or both, not '%s'\n", part.c_str());
        return 2;
      }
    } else if (arg == "--max-time" && has_value) {
      settings.max_time_s = std::atof(argv[++i]);
      max_time_given = true;
    } else if (arg == "--max-iterations" && has_value) {
      settings.max_iterations = std::atoi(argv[++i]);
    } else if (arg == "--resolutions" && has_value) {
      settings.resolutions = parse_list(argv[++i]);
    } else if (arg == "--mesh" && has_value) {
      settings.mesh_filters.push_back(argv[++i]);
    } else if (arg == "--out" && has_value) {
      settings.out_dir = argv[++i];
    } else if (arg == "--data" && has_value) {
      settings.data_dir = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: bench_accuracy [--part forward|design|both] [--mesh NAME]... [--max-time S] "
                   "[--max-iterations N] [--resolutions N,N,...] [--out DIR] [--data DIR] [--quick]\n");
      return 2;
    }
  }
  if (!(settings.max_time_s > 0) || settings.max_iterations <= 0 || settings.resolutions.empty()) {
    std::fprintf(stderr, "bench_accuracy: --max-time must be > 0 s, --max-iterations > 0, and --resolutions must "
                         "name a vertex count\n");
    return 2;
  }
  std::vector<Shape> shapes = {{"spot", "spot.obj"}, {"bunny", "stanford_bunny_1839.obj"}, {"blob", "retinal_bumpy_blob.off"}};
  shapes.erase(std::remove_if(shapes.begin(), shapes.end(),
                              [&](const Shape& s) {
                                return !settings.mesh_filters.empty() &&
                                       std::none_of(settings.mesh_filters.begin(), settings.mesh_filters.end(),
                                                    [&](const std::string& f) { return s.file.find(f) != std::string::npos; });
                              }),
               shapes.end());
  if (settings.quick) {
    if (shapes.size() > 1) shapes.resize(1);
    settings.resolutions = {1000, 2000};
    if (!max_time_given) settings.max_time_s = 10.0;
  }
  auto material = balloon::preset_material("silicone");
  if (!material) {
    std::fprintf(stderr, "bench_accuracy: %s\n", material.error().c_str());
    return 1;
  }
  std::filesystem::create_directories(settings.out_dir);
  balloon::bench::reset_peak_memory();
  std::printf("process resident at start: %.1f MB (in every row's peak)\n", balloon::bench::peak_memory_mb());
  if (settings.forward) forward_part(settings, *material, shapes);
  if (settings.design) design_part(settings, *material, shapes);
  std::printf("\nfiles: %s/{forward_sphere,forward_organic,design_runs,design_curves}.csv, design_levels.md, "
              "forward_error_vs_time.svg, design_error_vs_time.svg\n",
              settings.out_dir.c_str());
  return 0;
}
