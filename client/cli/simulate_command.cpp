/// `balloon simulate`: inflate a rest mesh and report the equilibrium (issue 2's CLI contract), run as
/// a job through the service (embedded by default, or --server).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "contract/job_result_files.hpp"
#include "exit_codes.hpp"
#include "job_command.hpp"
#include "job_watch.hpp"
#include "pressure_fall_line.hpp"
#include "result_files.hpp"
#include "service_connection.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* COMMAND = "simulate";

constexpr const char* HELP =
    "Usage: balloon simulate REST_MESH --material SPEC [--thickness MM] [--size MM]\n"
    "                        (--pressure KPA | --volume-ratio R) [--out FILE] [--json]\n"
    "       balloon simulate REST_MESH --material SPEC [--thickness MM] [--size MM]\n"
    "                        (--volume-ratio-range A:B | --pressure-range A:B) --points N [--out PATH] [--json]\n\n"
    "Inflates the closed rest mesh REST_MESH (OBJ, STL, PLY, OFF, glTF/GLB; coordinates in mm) to\n"
    "static equilibrium, either under a given pressure or to a given enclosed-volume ratio. Runs as a job\n"
    "on the service (an embedded one unless --server is given); on a terminal, progress goes to stderr.\n\n"
    "Options:\n"
    "  --material SPEC     rubber law: neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
    "                      hart-smith:G=0.1,k1=3e-4,k2=1.0 (moduli in MPa) | preset: silicone, latex |\n"
    "                      the name of a stored material (balloon materials list)\n"
    "  --thickness MM      rest membrane thickness in mm (default 0.5)\n"
    "  --size MM           first scale REST_MESH (about the origin) so its bounding-box diagonal is MM,\n"
    "                      e.g. for a mesh drawn in metres or units (default: keep its size)\n"
    "  --pressure KPA      inflate under this pressure (kPa, 0 < KPA <= 1e6)\n"
    "  --volume-ratio R    inflate until V / V_rest = R (0 < R <= 1e6; below 1 deflates); passes\n"
    "                      pressure maxima\n"
    "  --volume-ratio-range A:B\n"
    "                      the whole pressure-volume curve: N equilibria with V / V_rest from A to B\n"
    "                      (1 < A < B <= 1e6), spaced geometrically (equal ratios), followed as ONE\n"
    "                      continuation path (each point starts from the previous equilibrium; passes\n"
    "                      pressure maxima)\n"
    "  --pressure-range A:B\n"
    "                      the same over pressures A..B kPa (0 < A < B <= 1e6), spaced geometrically; under\n"
    "                      pressure control a pressure past a maximum gives the larger shape the balloon\n"
    "                      snaps to (the maximum is listed), or, where the pressure does not climb back\n"
    "                      by volume ratio 250, ends the path\n"
    "  --points N          number of curve points, 2..1000\n"
    "  --out FILE          write the inflated mesh (.obj, .stl or .ply), only if the run converged\n"
    "                      A curve writes curve.csv and curve.svg into FILE's folder (into FILE if it is a\n"
    "                      directory; the current folder without --out) and, if FILE ends in .obj, .stl or\n"
    "                      .ply, the last converged equilibrium to FILE\n"
    "  --json              print one JSON object on stdout instead of a summary\n"
    "  --help              this text\n\n"
    "JSON: the message balloon.v1.SimulateReport of proto/balloon/v1/balloon.proto in protobuf's JSON\n"
    "mapping (field names as in the .proto); for a curve, balloon.v1.CurveReport: `points` (one object per\n"
    "point: target, converged, volume_ratio, pressure_kpa, mean_stretch, max_stretch, unstable_modes,\n"
    "message) and `extrema` (kind maximum|minimum, point, volume_ratio, pressure_kpa).\n\n"
    "curve.csv: volume_ratio,pressure_kpa,mean_stretch,max_stretch,unstable_modes,converged; one row per\n"
    "point in path order (pressure in kPa, stretches and ratio dimensionless); a value never computed is\n"
    "an empty cell. unstable_modes: negative eigen-directions of the stiffness at the equilibrium (volume\n"
    "control: of the volume-constrained system; 0 = stable). The first point without an equilibrium ends\n"
    "the path: it and every later point are rows with converged=false (report.json's message says why).\n"
    "curve.svg: pressure against volume ratio (log scale), pressure maxima and minima marked.\n\n"
    "Exit codes: 0 converged (a curve: every point), 2 bad input (one line on stderr names it),\n"
    "3 not converged (the result is still printed, no --out mesh; a curve still writes curve.csv and\n"
    "curve.svg),\n"
    "5 server unreachable or busy, 6 not allowed, 8 the job failed, 130 interrupted (the job keeps\n"
    "running), 1 internal error.\n\n";

/// What the model added beyond the membrane, for both summaries: the sheet's bending and flipped cap slivers.
void append_model_notes(std::ostringstream& out, bool bending, int flipped_cap_slivers) {
  if (bending)
    out << "  bending        on: the membrane alone wrinkled with no stable state, so the sheet's bending\n"
           "                 stiffness (G h^3 / 3) was added\n";
  if (flipped_cap_slivers > 0)
    out << "  slivers        " << flipped_cap_slivers
        << " cap sliver(s) (a vertex almost on its opposite edge) simulated with their pair's other\n"
           "                 diagonal; no vertex moved\n";
}

/// The human summary of the service's report.
std::string summary_from_report(const v1::SimulateReport& report) {
  std::ostringstream out;
  out << (report.converged() ? "converged" : "NOT converged") << " after " << report.newton_iterations()
      << " Newton iterations (" << report.load_steps() << " load steps, " << report.factorizations()
      << " factorizations) in " << format("%.3f", report.time_s()) << " s\n";
  if (!report.message().empty()) out << "  " << report.message() << "\n";
  if (report.unstable_modes() > 0)
    out << "  stability      " << saddle_note(report.unstable_modes()) << "\n";
  append_model_notes(out, report.bending(), report.flipped_cap_slivers());
  out << "  material       " << report.material();
  if (!report.material_name().empty()) out << " (" << report.material_name() << ")";
  out << ", thickness " << format("%.6g", report.thickness_mm()) << " mm\n";
  out << "  mesh           " << report.vertices() << " vertices, " << report.faces() << " faces"
      << (report.flipped_orientation() ? " (flipped to face outwards)" : "") << "\n";
  out << "  pressure       " << format("%.6g", report.pressure_kpa()) << " kPa\n";
  out << "  volume         " << format("%.6g", report.volume_mm3()) << " mm^3 (rest "
      << format("%.6g", report.rest_volume_mm3()) << " mm^3, ratio " << format("%.6g", report.volume_ratio()) << ")\n";
  out << "  stretch        mean " << format("%.6g", report.mean_stretch()) << ", max "
      << format("%.6g", report.max_stretch()) << "\n";
  out << "  residual norm  " << format("%.3e", report.residual_norm()) << " N\n";
  if (report.has_pressure_fall()) out << pressure_fall_line(report.pressure_fall());
  return out.str();
}

Result<PreparedJob> prepare_simulate(const std::vector<std::string>& args) {
  std::vector<OptionSpec> options = simulate_option_specs();
  options.push_back({"out"});
  Result<ParsedArgs> parsed = parse_args(args, options);
  if (!parsed) return fail(parsed.error());
  Result<v1::SubmitJobRequest> request = simulate_request_from_args(*parsed);
  if (!request) return fail(request.error());
  PreparedJob job;
  job.request = std::move(*request);
  job.args = std::move(*parsed);
  job.file_field = "simulate.rest_mesh";
  job.file_path = job.args.positionals.front();
  return job;
}

bool is_curve(const PreparedJob& job) { return job.request.spec().simulate().has_curve(); }

bool names_mesh(const std::string& path) {
  const v1::MeshFormat format = mesh_format_from_path(path);
  return format == v1::MESH_FORMAT_OBJ || format == v1::MESH_FORMAT_STL || format == v1::MESH_FORMAT_PLY;
}

/// Where a curve's files go: --out's folder (--out itself if it is a directory), the current folder without it.
std::filesystem::path curve_folder(const std::optional<std::string>& out_path) {
  if (!out_path) return ".";
  std::error_code error;
  if (std::filesystem::is_directory(*out_path, error)) return *out_path;
  const std::filesystem::path parent = std::filesystem::path(*out_path).parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

std::string check_curve_outputs(const PreparedJob& job) {
  const std::optional<std::string> out_path = job.args.get("out");
  const std::filesystem::path folder = curve_folder(out_path);
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error))
    return "--out: folder '" + folder.string() + "' does not exist";
  if (::access(folder.c_str(), W_OK) != 0) return "--out: folder '" + folder.string() + "' is not writable";
  return "";
}

std::string check_simulate_outputs(const PreparedJob& job) {
  if (is_curve(job)) return check_curve_outputs(job);
  if (const auto out_path = job.args.get("out")) {
    if (const std::string problem = mesh_output_problem(*out_path); !problem.empty()) return "--out: " + problem;
  }
  return "";
}

/// The human summary of a curve: one line per point, the extrema, the stop reason.
std::string summary_from_curve(const v1::CurveReport& report) {
  std::ostringstream out;
  int converged = 0;
  for (const v1::CurvePointReport& point : report.points()) converged += point.converged() ? 1 : 0;
  out << (report.converged() ? "converged" : "NOT converged") << ": " << converged << " of " << report.points_size()
      << " points on one path (" << report.newton_iterations() << " Newton iterations, " << report.factorizations()
      << " factorizations) in " << format("%.3f", report.time_s()) << " s\n";
  if (!report.converged()) out << "  " << report.message() << "\n";
  append_model_notes(out, report.bending(), report.flipped_cap_slivers());
  out << "  material       " << report.material();
  if (!report.material_name().empty()) out << " (" << report.material_name() << ")";
  out << ", thickness " << format("%.6g", report.thickness_mm()) << " mm, " << report.vertices() << " vertices\n";
  out << "     V/V0    p (kPa)  mean stretch  max stretch  unstable\n";
  for (const v1::CurvePointReport& point : report.points()) {
    if (!point.converged()) {
      out << "  " << format("%7.4g", point.target()) << "  " << point.message() << "\n";
      continue;
    }
    out << "  " << format("%7.4g", point.volume_ratio()) << "  " << format("%9.5g", point.pressure_kpa()) << "  "
        << format("%12.5g", point.mean_stretch()) << "  " << format("%11.5g", point.max_stretch()) << "  "
        << (point.has_unstable_modes() ? format("%8.0f", point.unstable_modes()) : std::string("       ?")) << "\n";
  }
  const bool pressure_control = report.control() == "pressure";
  for (const v1::CurveExtremumReport& extremum : report.extrema()) {
    out << "  pressure " << extremum.kind() << " " << format("%.4g", extremum.pressure_kpa()) << " kPa at V/V0 "
        << format("%.4g", extremum.volume_ratio()) << " (stretch " << format("%.4g", std::cbrt(extremum.volume_ratio()))
        << ")";
    // Under pressure control the path passes extrema between points; after a maximum the balloon snaps.
    if (pressure_control && extremum.point() >= 0 && extremum.point() < report.points_size()) {
      const v1::CurvePointReport& after = report.points(extremum.point());
      out << ", passed on the way to " << format("%.4g", after.target()) << " kPa";
      if (extremum.kind() == "maximum" && after.converged())
        out << ": past it the balloon snaps to a larger shape (V/V0 " << format("%.4g", after.volume_ratio())
            << " at " << format("%.4g", after.pressure_kpa()) << " kPa)";
    }
    out << "\n";
  }
  return out.str();
}

int finish_curve(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                 const GlobalOptions& global) {
  const std::optional<std::string> out_path = job.args.get("out");
  const bool write_mesh = out_path && names_mesh(*out_path);
  grpc::Status status;
  Result<v1::JobResult> result = fetch_result(
      connection, job_id, write_mesh ? mesh_format_from_path(*out_path) : v1::MESH_FORMAT_OBJ, &status);
  if (!result) return report_error(COMMAND, result.error(), exit_code_for(status));
  const std::filesystem::path folder = curve_folder(out_path);
  for (const contract::JobResultFile& file : contract::job_result_files(*result)) {
    if (file.name != "curve.csv" && file.name != "curve.svg") continue;
    Result<bool> written = write_file_atomically((folder / file.name).string(), file.bytes);
    if (!written) return report_error(COMMAND, file.name + ": " + written.error(), EXIT_INTERNAL);
  }
  if (global.json)
    std::cout << contract::result_report_json(*result) << std::flush;
  else
    std::cout << summary_from_curve(result->curve_report()) << "  files          " << (folder / "curve.csv").string()
              << ", " << (folder / "curve.svg").string() << "\n"
              << std::flush;
  if (write_mesh) {
    if (result->curve_report().last_converged_point() < 0) {
      std::fprintf(stderr, "balloon simulate: no point converged; %s not written\n", out_path->c_str());
    } else {
      Result<bool> written = write_file_atomically(*out_path, result->inflated_mesh().data());
      if (!written) return report_error(COMMAND, "--out: " + written.error(), EXIT_INTERNAL);
    }
  }
  return result->converged() ? EXIT_OK : EXIT_NOT_CONVERGED;
}

int finish_simulate(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                    const GlobalOptions& global) {
  if (is_curve(job)) return finish_curve(connection, job, job_id, global);
  const std::optional<std::string> out_path = job.args.get("out");
  grpc::Status status;
  Result<v1::JobResult> result =
      fetch_result(connection, job_id, out_path ? mesh_format_from_path(*out_path) : v1::MESH_FORMAT_OBJ, &status,
                   true);  // --out is the inflated mesh; the rest mesh is the user's own file
  if (!result) return report_error(COMMAND, result.error(), exit_code_for(status));

  if (global.json)
    std::cout << contract::result_report_json(*result) << std::flush;
  else
    std::cout << summary_from_report(result->simulate_report()) << std::flush;

  if (!result->converged()) {
    if (out_path) std::fprintf(stderr, "balloon simulate: not converged; %s not written\n", out_path->c_str());
    return EXIT_NOT_CONVERGED;
  }
  if (out_path) {
    Result<bool> written = write_file_atomically(*out_path, result->inflated_mesh().data());
    if (!written) return report_error(COMMAND, "--out: " + written.error(), EXIT_INTERNAL);
  }
  return EXIT_OK;
}

}  // namespace

std::string simulate_summary(const v1::SimulateReport& report) { return summary_from_report(report); }

std::string curve_summary(const v1::CurveReport& report) { return summary_from_curve(report); }

const JobCommand& simulate_job_command() {
  static const JobCommand PARTS{"simulate", HELP, {"out"}, prepare_simulate, check_simulate_outputs, finish_simulate};
  return PARTS;
}

int run_simulate_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  return run_job_command(simulate_job_command(), args, global, false);
}

}  // namespace balloon::cli
