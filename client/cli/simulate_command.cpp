/// `balloon simulate`: inflate a rest mesh and report the equilibrium (issue 2's CLI contract), run as
/// a job through the service (embedded by default, or --server).
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <sstream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "contract/job_result_files.hpp"
#include "exit_codes.hpp"
#include "job_command.hpp"
#include "job_watch.hpp"
#include "result_files.hpp"
#include "service_connection.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* COMMAND = "simulate";

constexpr const char* HELP =
    "Usage: balloon simulate REST_MESH --material SPEC [--thickness MM]\n"
    "                        (--pressure KPA | --volume-ratio R) [--out FILE] [--json]\n\n"
    "Inflates the closed rest mesh REST_MESH (OBJ, STL, PLY, OFF, glTF/GLB; coordinates in mm) to\n"
    "static equilibrium, either under a given pressure or to a given enclosed-volume ratio. Runs as a job\n"
    "on the service (an embedded one unless --server is given); on a terminal, progress goes to stderr.\n\n"
    "Options:\n"
    "  --material SPEC     rubber law: neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
    "                      hart-smith:G=0.1,k1=3e-4,k2=1.0 (moduli in MPa) | preset: silicone, latex |\n"
    "                      the name of a stored material (balloon materials list)\n"
    "  --thickness MM      rest membrane thickness in mm (default 0.5)\n"
    "  --pressure KPA      inflate under this pressure (kPa, > 0)\n"
    "  --volume-ratio R    inflate until V / V_rest = R (> 0); passes pressure maxima\n"
    "  --out FILE          write the inflated mesh (.obj, .stl or .ply), only if the run converged\n"
    "  --json              print one JSON object on stdout instead of a summary\n"
    "  --help              this text\n\n"
    "JSON: the message balloon.v1.SimulateReport of proto/balloon/v1/balloon.proto in protobuf's JSON\n"
    "mapping (field names as in the .proto).\n\n"
    "Exit codes: 0 converged, 2 bad input (one line on stderr names it), 3 not converged (the result is\n"
    "still printed, no --out file), 5 server unreachable or busy, 6 not allowed, 8 the job failed,\n"
    "130 interrupted (the job keeps running), 1 internal error.\n\n";

std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), pattern, value);
  return buffer;
}

/// The human summary of the service's report.
std::string summary_from_report(const v1::SimulateReport& report) {
  std::ostringstream out;
  out << (report.converged() ? "converged" : "NOT converged") << " after " << report.newton_iterations()
      << " Newton iterations (" << report.load_steps() << " load steps, " << report.factorizations()
      << " factorizations) in " << format("%.3f", report.time_s()) << " s\n";
  if (!report.message().empty()) out << "  " << report.message() << "\n";
  if (report.unstable_modes() > 0)
    out << "  stability      a saddle under volume control: " << report.unstable_modes()
        << " unstable direction(s) (wrinkling or symmetry breaking; the real balloon may take another shape)\n";
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

std::string check_simulate_outputs(const PreparedJob& job) {
  if (const auto out_path = job.args.get("out")) {
    if (const std::string problem = mesh_output_problem(*out_path); !problem.empty()) return "--out: " + problem;
  }
  return "";
}

int finish_simulate(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                    const GlobalOptions& global) {
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

const JobCommand& simulate_job_command() {
  static const JobCommand PARTS{"simulate", HELP, {"out"}, prepare_simulate, check_simulate_outputs, finish_simulate};
  return PARTS;
}

int run_simulate_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  return run_job_command(simulate_job_command(), args, global, false);
}

}  // namespace balloon::cli
