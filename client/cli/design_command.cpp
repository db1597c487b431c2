/// `balloon design`: the inverse design of issue 4 as submit + watch + result through the service
/// (embedded by default, or --server), writing rest.obj, inflated.obj, mold.stl, report.json and
/// convergence.csv into one directory.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "contract/job_result_files.hpp"
#include "design/balloon_design.hpp"
#include "exit_codes.hpp"
#include "field_flags.hpp"
#include "jobs/design_job.hpp"
#include "job_watch.hpp"
#include "material/material.hpp"
#include "material_argument.hpp"
#include "mesh/mesh_io.hpp"
#include "job_command.hpp"
#include "pressure_fall_line.hpp"
#include "result_files.hpp"
#include "service_connection.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* COMMAND = "design";

constexpr const char* HELP =
    "Usage: balloon design TARGET_MESH --material SPEC [--thickness MM] [--size MM] [--resolution N]\n"
    "                      [--scale S | --volume-ratio R] [--method adjoint|alm] [--nozzle auto|X,Y,Z[,R]]\n"
    "                      [--max-time S] [--tolerance-samples N] [--out-dir DIR] [--json]\n\n"
    "Finds the rest shape of a rubber balloon whose inflation matches the closed target surface\n"
    "TARGET_MESH (OBJ, STL, PLY, OFF, glTF/GLB; coordinates in mm). Runs as a job on the service (an\n"
    "embedded one unless --server is given). Writes into DIR:\n"
    "  rest.obj          the balloon to fabricate (mm)\n"
    "  inflated.obj      its predicted inflated shape (mm)\n"
    "  mold.stl          the rest shape with an inflation tube at the nozzle: the dip/brush mold\n"
    "  report.json       the report (see below)\n"
    "  convergence.csv   time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n\n"
    "Options:\n"
    "  --material SPEC        rubber law: neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
    "                         hart-smith:G=0.1,k1=3e-4,k2=1.0 (moduli in MPa) | preset: silicone, latex |\n"
    "                         the name of a stored material (balloon materials list)\n"
    "  --thickness MM         rest membrane thickness in mm (default 0.5)\n"
    "  --size MM              scale the target so its bounding-box diagonal is MM (default: keep its size)\n"
    "  --resolution N         remesh the target to about N vertices (default 4000); 0 keeps its mesh\n"
    "  --scale S              start from the target scaled by S (0.1 <= S < 1), or ...\n"
    "  --volume-ratio R       ... from the target scaled to 1/R of its volume (1 < R <= 1000, default 8);\n"
    "                         adjoint holds that rest volume, so its design inflates by R; alm (the\n"
    "                         paper's method, at the start's pressure) lets the rest volume follow, and\n"
    "                         the report gives the ratio its design inflates by. Where the rubber's\n"
    "                         pressure falls as it stretches (latex: volume ratio 2.55 to 62.4, x8\n"
    "                         included), long or thin parts can bulge one at a time; the summary's\n"
    "                         `rubber` line and report.json's pressure_fall say how much of the design\n"
    "                         is there\n"
    "  --method M             optimizer: adjoint (reduced space) or alm (augmented Lagrangian);\n"
    "                         default: the optimizer's default\n"
    "  --nozzle auto|X,Y,Z[,R]  hold the rest vertices within R mm (default 5% of the bbox diagonal) of\n"
    "                         the target point X,Y,Z (mm), or of its lowest point; default: none (the mold's\n"
    "                         tube then goes at the rest shape's lowest point)\n"
    "  --max-time S           stop the optimizer after S seconds and keep the best design (default: none)\n"
    "  --tolerance-samples N  also inflate the design N times per level with random per-element thickness\n"
    "                         errors of 10% and 20% and report the mean deviation (default 0: skip)\n"
    "  --out-dir DIR          where to write the five files (default: ./<TARGET name>-design); created\n"
    "                         if missing, files in it are replaced\n"
    "  --json                 print the report JSON on stdout instead of a summary\n"
    "  --help                 this text\n\n"
    "report.json: the message balloon.v1.DesignReport of proto/balloon/v1/balloon.proto in protobuf's JSON\n"
    "mapping (field names as in the .proto); an error never computed (no design, no baseline) is null.\n"
    "mold.stl is built by the server (none when the report gives a mold_problem).\n\n"
    "Progress: a bar with iteration, current average error and ETA on a terminal; plain lines on stderr\n"
    "otherwise. Exit codes: 0 converged, 2 bad input (one line on stderr names it, before any work),\n"
    "3 finished without converging (the files are still written: the best design found), 5 server\n"
    "unreachable or busy, 6 not allowed, 8 the job failed, 130 interrupted (the job keeps running),\n"
    "1 internal error.\n\n";

std::vector<OptionSpec> design_option_specs() {
  return {{"material"}, {"thickness"}, {"size"},      {"resolution"}, {"scale"},
          {"volume-ratio"}, {"method"}, {"nozzle"},   {"max-time"},   {"tolerance-samples"},
          {"out-dir"}};
}

/// Checks TARGET_MESH and the flags locally (so errors name the flag) and builds the request.
Result<v1::SubmitJobRequest> design_request_from_args(const ParsedArgs& args) {
  if (args.positionals.empty()) return fail("missing TARGET_MESH (see --help)");
  if (args.positionals.size() > 1)
    return fail("expected one TARGET_MESH, got " + std::to_string(args.positionals.size()) + " paths");
  const std::string& mesh_path = args.positionals.front();

  v1::SubmitJobRequest request;
  v1::DesignJob* job = request.mutable_spec()->mutable_design();

  const std::optional<std::string> spec = args.get("material");
  if (!spec) return fail("missing --material SPEC");
  Result<v1::MaterialRef> material = material_reference(*spec);
  if (!material) return fail(material.error());
  *job->mutable_material() = std::move(*material);

  jobs::DesignParameters parameters;
  const auto number = [&](const char* name, auto assign) -> std::string {
    if (const auto text = args.get(name)) {
      Result<double> value = parse_number(name, *text);
      if (!value) return value.error();
      assign(*value);
    }
    return "";
  };
  std::string problem;
  if (problem = number("thickness", [&](double v) { parameters.thickness_mm = v; }); !problem.empty()) return fail(problem);
  if (problem = number("size", [&](double v) { parameters.size_mm = v; }); !problem.empty()) return fail(problem);
  if (problem = number("scale", [&](double v) { parameters.scale = v; }); !problem.empty()) return fail(problem);
  if (problem = number("volume-ratio", [&](double v) { parameters.volume_ratio = v; }); !problem.empty())
    return fail(problem);
  if (problem = number("max-time", [&](double v) { parameters.max_time_s = v; }); !problem.empty()) return fail(problem);
  if (const auto text = args.get("resolution")) {
    Result<long long> value = parse_integer("resolution", *text, 0, 1000000);
    if (!value) return fail(value.error());
    parameters.resolution = static_cast<int>(*value);
  }
  if (const auto text = args.get("tolerance-samples")) {
    Result<long long> value = parse_integer("tolerance-samples", *text, 0, jobs::MAX_TOLERANCE_SAMPLES);
    if (!value) return fail(value.error());
    parameters.tolerance_samples = static_cast<int>(*value);
  }
  if (const auto text = args.get("method")) parameters.method = *text;
  if (const auto text = args.get("nozzle")) {
    if (text->empty()) return fail("--nozzle: give auto or X,Y,Z[,RADIUS] (mm)");
    parameters.nozzle = *text;
  }
  if (const std::vector<jobs::FieldProblem> found = jobs::design_parameter_problems(parameters); !found.empty())
    return fail(message_naming_flags("design", found));

  job->set_thickness_mm(parameters.thickness_mm);
  job->set_size_mm(parameters.size_mm);
  // Absent: the server's default; 0 keeps the target's mesh (the same meaning on the wire).
  if (args.get("resolution")) job->set_resolution(parameters.resolution);
  if (parameters.scale) job->set_scale(*parameters.scale);
  if (parameters.volume_ratio) job->set_volume_ratio(*parameters.volume_ratio);
  job->set_method(parameters.method);
  job->set_nozzle(parameters.nozzle);
  job->set_max_time_s(parameters.max_time_s);
  job->set_tolerance_samples(parameters.tolerance_samples);

  const v1::MeshFormat format = mesh_format_from_path(mesh_path);
  std::error_code error;
  if (!std::filesystem::exists(mesh_path, error)) return fail("cannot read mesh '" + mesh_path + "': no such file");
  if (format == v1::MESH_FORMAT_UNSPECIFIED)
    return fail("cannot read mesh '" + mesh_path + "': unknown extension (obj, stl, ply, off, gltf, glb)");
  std::ifstream in(mesh_path, std::ios::binary);
  if (!in) return fail("cannot read mesh '" + mesh_path + "'");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  job->mutable_target_mesh()->set_data(bytes.str());
  job->mutable_target_mesh()->set_format(format);
  return request;
}

/// A report number formatted with `pattern`, or "n/a" when the report has none (never computed).
std::string shown_number(bool has, double value, const char* pattern, double scale = 1.0) {
  return has ? format(pattern, scale * value) : "n/a";
}

std::string summary_from_report(const v1::DesignReport& report, const std::string& out_dir) {
  std::ostringstream out;
  out << (report.converged() ? "converged" : "NOT converged")
      << (report.stop_reason().empty() ? std::string() : " (" + report.stop_reason() + ")") << " after "
      << report.iterations() << " iterations in " << format("%.3f", report.time_s()) << " s (" << report.method()
      << ")\n";
  if (!report.message().empty()) out << "  " << report.message() << "\n";
  out << "  error          avg " << shown_number(report.has_avg_error_mm(), report.avg_error_mm(), "%.4g") << " mm ("
      << shown_number(report.has_avg_error_rel(), report.avg_error_rel(), "%.3g", 100.0) << "%), max "
      << shown_number(report.has_max_error_mm(), report.max_error_mm(), "%.4g") << " mm ("
      << shown_number(report.has_max_error_rel(), report.max_error_rel(), "%.3g", 100.0) << "%) of bbox diagonal "
      << format("%.4g", report.bbox_diag_mm()) << " mm\n";
  out << "  baseline       avg "
      << shown_number(report.has_baseline_avg_error_mm(), report.baseline_avg_error_mm(), "%.4g") << " mm, max "
      << shown_number(report.has_baseline_max_error_mm(), report.baseline_max_error_mm(), "%.4g")
      << " mm (the downscaled target inflated)\n";
  out << "  inflation      " << shown_number(report.has_pressure_kpa(), report.pressure_kpa(), "%.5g")
      << " kPa, volume ratio " << shown_number(report.has_volume_ratio(), report.volume_ratio(), "%.4g") << ", " << report.vertices() << " vertices\n";
  if (report.has_from_rest()) {
    const v1::RestInflationCheck& check = report.from_rest();
    out << "  from rest      ";
    if (check.converged())
      out << (check.another_shape() ? "ANOTHER SHAPE: " : "the design's shape: ") << "avg "
          << shown_number(check.has_avg_error_mm(), check.avg_error_mm(), "%.4g") << " mm ("
          << shown_number(check.has_avg_error_rel(), check.avg_error_rel(), "%.3g", 100.0) << "%) at "
          << shown_number(check.has_pressure_kpa(), check.pressure_kpa(), "%.5g") << " kPa, "
          << shown_number(check.has_deviation_mm(), check.deviation_mm(), "%.3g")
          << " mm from the design's shape (inflated as balloon simulate does)\n";
    else
      out << check.message() << "\n";
    if (check.converged() && check.unstable_modes() > 0)
      out << "  stability      from rest, " << saddle_note(check.unstable_modes()) << "\n";
  }
  if (report.has_pressure_fall()) out << pressure_fall_line(report.pressure_fall());
  if (report.has_tolerance() && report.tolerance().levels_size() > 0) {
    out << "  tolerance     ";
    for (const v1::ToleranceLevel& level : report.tolerance().levels())
      out << " " << format("%.0f", 100.0 * level.perturbation()) << "% thickness: "
          << format("%.3g", level.mean_deviation_mm()) << " mm;";
    out << "\n";
  }
  if (report.has_mold_problem()) out << "  mold           not written: " << report.mold_problem() << "\n";
  out << "  written to     " << out_dir << "\n";
  return out.str();
}

std::string out_dir_of(const PreparedJob& job) {
  return job.args.get("out-dir").value_or(std::filesystem::path(job.file_path).stem().string() + "-design");
}

Result<PreparedJob> prepare_design(const std::vector<std::string>& args) {
  Result<ParsedArgs> parsed = parse_args(args, design_option_specs());
  if (!parsed) return fail(parsed.error());
  Result<v1::SubmitJobRequest> request = design_request_from_args(*parsed);
  if (!request) return fail(request.error());
  PreparedJob job;
  job.request = std::move(*request);
  job.args = std::move(*parsed);
  job.file_field = "design.target_mesh";
  job.file_path = job.args.positionals.front();
  return job;
}

std::string check_design_outputs(const PreparedJob& job) { return output_directory_problem(out_dir_of(job)); }

int finish_design(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                  const GlobalOptions& global) {
  grpc::Status status;
  Result<v1::JobResult> result = fetch_result(connection, job_id, v1::MESH_FORMAT_OBJ, &status);
  if (!result) return report_error(COMMAND, result.error(), exit_code_for(status));
  const std::string out_dir = out_dir_of(job);
  Result<std::vector<std::string>> written = write_result_files(*result, out_dir);
  if (!written) return report_error(COMMAND, written.error(), EXIT_INTERNAL);
  if (global.json)
    std::cout << contract::result_report_json(*result) << std::flush;
  else
    std::cout << design_summary(result->design_report(), out_dir) << std::flush;
  return result->converged() ? EXIT_OK : EXIT_NOT_CONVERGED;
}

}  // namespace

std::string design_summary(const v1::DesignReport& report, const std::string& out_dir) {
  std::string summary = summary_from_report(report, out_dir);
  if (out_dir.empty()) summary.erase(summary.rfind("  written to"));
  return summary;
}

const JobCommand& design_job_command() {
  static const JobCommand COMMAND_PARTS{"design", HELP, {"out-dir"}, prepare_design, check_design_outputs,
                                        finish_design};
  return COMMAND_PARTS;
}

int run_design_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  return run_job_command(design_job_command(), args, global, false);
}

}  // namespace balloon::cli
