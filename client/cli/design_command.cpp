/// `balloon design`: the inverse design of issue 4 as submit + watch + result through the service
/// (embedded by default, or --server), writing rest.obj, inflated.obj, mold.stl, report.json and
/// convergence.csv into one directory.
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
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
#include "design/balloon_design.hpp"
#include "exit_codes.hpp"
#include "jobs/design_job.hpp"
#include "job_watch.hpp"
#include "material/material.hpp"
#include "material_argument.hpp"
#include "mesh/mesh_io.hpp"
#include "service_connection.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;
using google::protobuf::Struct;
using google::protobuf::Value;

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
    "  report.json       the report (keys below)\n"
    "  convergence.csv   time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n\n"
    "Options:\n"
    "  --material SPEC        rubber law: neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
    "                         hart-smith:G=0.1,k1=3e-4,k2=1.0 (moduli in MPa) | preset: silicone, latex |\n"
    "                         the name of a stored material (balloon materials list)\n"
    "  --thickness MM         rest membrane thickness in mm (default 0.5)\n"
    "  --size MM              scale the target so its bounding-box diagonal is MM (default: keep its size)\n"
    "  --resolution N         remesh the target to about N vertices (default 4000); 0 keeps its mesh\n"
    "  --scale S              start from the target scaled by S (0 < S), or ...\n"
    "  --volume-ratio R       ... from the target scaled to 1/R of its volume (default 8)\n"
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
    "Report keys: converged, stop_reason (matched, optimal, stalled, time_limit, iteration_limit,\n"
    "start_failed, cancelled; converged means matched or optimal), method, avg_error_mm, max_error_mm,\n"
    "avg_error_rel, max_error_rel (null when there is no design),\n"
    "bbox_diag_mm, pressure_kpa, volume_ratio, iterations, time_s, vertices, active_terms,\n"
    "baseline_avg_error_mm, baseline_max_error_mm (null when the start was not inflated), distance_energy,\n"
    "residual_norm (N), material,\n"
    "thickness_mm, message, preparation, nozzle, mold, tolerance (with --tolerance-samples), convergence.\n\n"
    "Progress: a bar with iteration, current average error and ETA on a terminal; plain lines on stderr\n"
    "otherwise. Exit codes: 0 converged, 2 bad input (one line on stderr names it, before any work),\n"
    "3 finished without converging (the files are still written: the best design found), 5 server\n"
    "unreachable or busy, 6 not allowed, 8 the job failed, 130 interrupted (the job is cancelled),\n"
    "1 internal error.\n\n";

std::vector<OptionSpec> design_option_specs() {
  return {{"material"}, {"thickness"}, {"size"},      {"resolution"}, {"scale"},
          {"volume-ratio"}, {"method"}, {"nozzle"},   {"max-time"},   {"tolerance-samples"},
          {"out-dir"},  {"json", false}, {"help", false}};
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
  if (const std::string found = jobs::design_parameters_problem(parameters); !found.empty()) return fail(found);

  job->set_thickness_mm(parameters.thickness_mm);
  job->set_size_mm(parameters.size_mm);
  // On the wire 0 means the server's default and < 0 keeps the target's mesh.
  job->set_resolution(parameters.resolution == 0 ? -1 : parameters.resolution);
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

const Value* field(const Struct& object, const std::string& key) {
  const auto it = object.fields().find(key);
  return it == object.fields().end() ? nullptr : &it->second;
}
double number_field(const Struct& object, const std::string& key) {
  const Value* value = field(object, key);
  return value != nullptr ? value->number_value() : 0.0;
}


/// The convergence log from the report's parallel arrays.
std::vector<ConvergenceSample> convergence_from_report(const Struct& report) {
  std::vector<ConvergenceSample> log;
  const Value* convergence = field(report, "convergence");
  if (convergence == nullptr || !convergence->has_struct_value()) return log;
  const Struct& columns = convergence->struct_value();
  const auto column = [&](const char* key) {
    std::vector<double> values;
    if (const Value* array = field(columns, key); array != nullptr && array->has_list_value())
      for (const Value& v : array->list_value().values()) values.push_back(v.number_value());
    return values;
  };
  const std::vector<double> time = column("time_s"), iteration = column("iteration"), avg = column("avg_error_mm"),
                            max = column("max_error_mm"), residual = column("residual_norm");
  const std::size_t rows = std::min({time.size(), iteration.size(), avg.size(), max.size(), residual.size()});
  for (std::size_t i = 0; i < rows; ++i)
    log.push_back({time[i], static_cast<int>(std::lround(iteration[i])), avg[i], max[i], residual[i]});
  return log;
}

std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), pattern, value);
  return buffer;
}

/// A report number formatted with `pattern`, or "n/a" when the report has none (null: never computed).
std::string shown_number(const Struct& object, const std::string& key, const char* pattern, double scale = 1.0) {
  const Value* value = field(object, key);
  if (value == nullptr || !value->has_number_value()) return "n/a";
  return format(pattern, scale * value->number_value());
}

std::string summary_from_report(const Struct& report, const std::string& out_dir) {
  const Value* converged = field(report, "converged");
  std::ostringstream out;
  const Value* stop_reason = field(report, "stop_reason");
  out << (converged != nullptr && converged->bool_value() ? "converged" : "NOT converged")
      << (stop_reason != nullptr ? " (" + stop_reason->string_value() + ")" : std::string()) << " after "
      << number_field(report, "iterations") << " iterations in " << format("%.3f", number_field(report, "time_s"))
      << " s (" << (field(report, "method") ? field(report, "method")->string_value() : "") << ")\n";
  if (const Value* message = field(report, "message"); message != nullptr && !message->string_value().empty())
    out << "  " << message->string_value() << "\n";
  out << "  error          avg " << shown_number(report, "avg_error_mm", "%.4g") << " mm ("
      << shown_number(report, "avg_error_rel", "%.3g", 100.0) << "%), max "
      << shown_number(report, "max_error_mm", "%.4g") << " mm ("
      << shown_number(report, "max_error_rel", "%.3g", 100.0) << "%) of bbox diagonal "
      << format("%.4g", number_field(report, "bbox_diag_mm")) << " mm\n";
  out << "  baseline       avg " << shown_number(report, "baseline_avg_error_mm", "%.4g") << " mm, max "
      << shown_number(report, "baseline_max_error_mm", "%.4g") << " mm (the downscaled target inflated)\n";
  out << "  inflation      " << format("%.5g", number_field(report, "pressure_kpa")) << " kPa, volume ratio "
      << format("%.4g", number_field(report, "volume_ratio")) << ", " << number_field(report, "vertices")
      << " vertices\n";
  if (const Value* tolerance = field(report, "tolerance"); tolerance != nullptr && tolerance->has_struct_value()) {
    if (const Value* levels = field(tolerance->struct_value(), "levels"); levels != nullptr && levels->has_list_value()) {
      out << "  tolerance     ";
      for (const Value& level : levels->list_value().values())
        out << " " << format("%.0f", 100.0 * number_field(level.struct_value(), "perturbation")) << "% thickness: "
            << format("%.3g", number_field(level.struct_value(), "mean_deviation_mm")) << " mm;";
      out << "\n";
    }
  }
  if (const Value* problem = field(report, "mold_problem"); problem != nullptr)
    out << "  mold           not written: " << problem->string_value() << "\n";
  out << "  written to     " << out_dir << "\n";
  return out.str();
}

/// On a terminal: a bar with iteration, average error and ETA; otherwise plain lines (ProgressPrinter).
class DesignProgress {
 public:
  DesignProgress(bool terminal, double max_time_s) : m_terminal(terminal), m_max_time_s(max_time_s), m_lines(true) {}
  ~DesignProgress() {
    if (m_open) std::fputc('\n', stderr);
  }
  void operator()(const v1::JobEvent& event) {
    if (!m_terminal || !event.has_progress() || event.progress().phase() != "design") {
      if (m_open) std::fputc('\n', stderr);
      m_open = false;
      m_lines(event);
      return;
    }
    const v1::Progress& p = event.progress();
    const int budget = DesignOptions{}.max_iterations;
    double fraction = std::min(1.0, static_cast<double>(p.iteration()) / budget);
    double eta = p.iteration() > 0 ? p.elapsed_s() / p.iteration() * std::max(0, budget - p.iteration()) : -1.0;
    if (m_max_time_s > 0.0) {
      fraction = std::max(fraction, std::min(1.0, p.elapsed_s() / m_max_time_s));
      const double left = std::max(0.0, m_max_time_s - p.elapsed_s());
      eta = eta < 0.0 ? left : std::min(eta, left);
    }
    constexpr int WIDTH = 30;
    const int filled = static_cast<int>(std::lround(fraction * WIDTH));
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(WIDTH - filled), '-');
    std::fprintf(stderr, "\r\033[K[%s] it %d  avg error %.3g mm  max %.3g mm  %.1f s  ETA %s", bar.c_str(),
                 p.iteration(), p.avg_error_mm(), p.max_error_mm(), p.elapsed_s(),
                 eta < 0.0 ? "?" : (format("%.0f", eta) + " s").c_str());
    std::fflush(stderr);
    m_open = true;
  }

 private:
  bool m_terminal;
  double m_max_time_s;
  ProgressPrinter m_lines;
  bool m_open = false;
};

}  // namespace

int run_design_command(const std::vector<std::string>& args) {
  std::vector<OptionSpec> options = design_option_specs();
  for (const OptionSpec& spec : connection_option_specs()) options.push_back(spec);
  Result<ParsedArgs> parsed = parse_args(args, options);
  if (!parsed) return report_error(COMMAND, parsed.error(), EXIT_BAD_INPUT);
  if (parsed->has("help")) {
    std::fputs(HELP, stdout);
    std::fputs(connection_help(), stdout);
    return EXIT_OK;
  }
  // Every local check comes before any connection, so the cheapest problems are reported first.
  Result<v1::SubmitJobRequest> request = design_request_from_args(*parsed);
  if (!request) return report_error(COMMAND, request.error(), EXIT_BAD_INPUT);
  const std::string mesh_path = parsed->positionals.front();
  const std::string out_dir =
      parsed->get("out-dir").value_or(std::filesystem::path(mesh_path).stem().string() + "-design");
  {
    std::error_code error;
    std::filesystem::create_directories(out_dir, error);
    if (error || !std::filesystem::is_directory(out_dir))
      return report_error(COMMAND, "--out-dir: cannot create directory '" + out_dir + "'", EXIT_BAD_INPUT);
    if (::access(out_dir.c_str(), W_OK) != 0)
      return report_error(COMMAND, "--out-dir: directory '" + out_dir + "' is not writable", EXIT_BAD_INPUT);
  }

  auto connection = ServiceConnection::open(connection_options(*parsed));
  if (!connection) return report_error(COMMAND, connection.error(), EXIT_UNAVAILABLE);

  v1::SubmitJobResponse submitted;
  if (const grpc::Status status = (*connection)->submit(*request, &submitted); !status.ok())
    return report_error(COMMAND, message_naming_file(status, "target_mesh", mesh_path), exit_code_for(status));
  const std::string job_id = submitted.job().id();

  DesignProgress progress(isatty(STDERR_FILENO) == 1, request->spec().design().max_time_s());
  if (const int code = follow_to_completion(**connection, COMMAND, job_id,
                                           [&](const v1::JobEvent& event) { progress(event); });
      code != EXIT_OK)
    return code;

  v1::GetResultRequest result_request;
  result_request.set_job_id(job_id);
  result_request.set_format(v1::MESH_FORMAT_OBJ);
  v1::JobResult result;
  {
    grpc::ClientContext context;
    (*connection)->prepare(context);
    const grpc::Status status = (*connection)->stub().GetResult(&context, result_request, &result);
    if (!status.ok()) return report_error(COMMAND, status.error_message(), exit_code_for(status));
  }

  Struct report;
  if (!google::protobuf::util::JsonStringToMessage(result.report_json(), &report).ok())
    return report_error(COMMAND, "the service returned an unreadable report", EXIT_INTERNAL);
  const std::filesystem::path directory(out_dir);
  const auto write = [&](const char* name, const std::string& bytes) -> std::string {
    Result<bool> written = write_file_atomically((directory / name).string(), bytes);
    return written ? std::string() : std::string(name) + ": " + written.error();
  };
  std::string problem;
  if (problem = write("rest.obj", result.rest_mesh().data()); !problem.empty())
    return report_error(COMMAND, problem, EXIT_INTERNAL);
  if (problem = write("inflated.obj", result.inflated_mesh().data()); !problem.empty())
    return report_error(COMMAND, problem, EXIT_INTERNAL);
  if (problem = write("report.json", result.report_json() + "\n"); !problem.empty())
    return report_error(COMMAND, problem, EXIT_INTERNAL);
  if (problem = write("convergence.csv", jobs::convergence_csv(convergence_from_report(report))); !problem.empty())
    return report_error(COMMAND, problem, EXIT_INTERNAL);
  // The mold is built here from the stored rest mesh with the tube the job chose (jobs::mold_from_report
  // is the one place that builds it, for the web gateway too), since the store keeps meshes and the report only.
  if (const Value* mold = field(report, "mold"); mold != nullptr && mold->has_struct_value()) {
    Result<TriMesh> rest = read_mesh_from_memory(result.rest_mesh().data(), "obj");
    if (!rest) return report_error(COMMAND, "rest mesh from the service: " + rest.error(), EXIT_INTERNAL);
    Result<TriMesh> built = jobs::mold_from_report(*rest, result.report_json());
    if (!built) {
      std::fprintf(stderr, "balloon design: warning: mold.stl not written: %s\n", built.error().c_str());
    } else if (problem = write("mold.stl", write_mesh_to_memory(*built, "stl")); !problem.empty()) {
      return report_error(COMMAND, problem, EXIT_INTERNAL);
    }
  } else {
    std::error_code ignored;
    std::filesystem::remove(directory / "mold.stl", ignored);  // never leave a stale mold from an earlier run
  }

  if (parsed->has("json"))
    std::cout << result.report_json() << std::endl;
  else
    std::cout << summary_from_report(report, out_dir) << std::flush;
  return result.converged() ? EXIT_OK : EXIT_NOT_CONVERGED;
}

}  // namespace balloon::cli
