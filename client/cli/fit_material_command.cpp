/// `balloon fit-material`: fit rubber laws to measurement files, print, plot, and optionally store the fit
/// in the service's material library. The data are checked locally (server/jobs/fit_job), then the fit
/// runs as a fit_material job on the service (embedded by default), which also stores it under --name.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "job_watch.hpp"
#include "jobs/fit_job.hpp"
#include "service_connection.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* HELP =
    "Usage: balloon fit-material DATA.csv [DATA2.csv ...] --model hart-smith|mooney-rivlin|neo-hookean|all\n"
    "         (--test bulge --radius MM --thickness MM | --test uniaxial|equibiaxial|pure-shear)\n"
    "         [--name NAME] [--plot FILE.svg] [--json]\n\n"
    "Fits the law(s) to all files jointly by nonlinear least squares and prints the constants (moduli in MPa)\n"
    "and the residuals. A file takes the --test (and --radius, --thickness) given before it, else the first one\n"
    "on the line: `--test uniaxial a.csv --test equibiaxial b.csv`.\n"
    "  bulge data: columns pressure_kpa,extension_ratio[,apex_height_mm]; simulated by FEM on the clamped disc\n"
    "  stress tables: columns stretch,nominal_stress_MPa\n"
    "  --name NAME     store the fit (the best one with `all`) in the material library, with its provenance\n"
    "  --plot FILE     write an SVG of the data and each model's curve\n"
    "  --json          one JSON object (a list with `all`): model, params, rms_residual, max_residual, points\n\n"
    "Exit codes: 0 ok, 1 output not written, 2 bad input or data, 5 service unreachable, 6 name not allowed.\n\n";

/// Options placed per file: the latest value before the file, else the first one on the line.
struct PlacedOption {
  size_t files_before = 0;  ///< how many files came before this option
  std::string value;
};

std::optional<std::string> placed_value(const std::vector<PlacedOption>& options, size_t file_index) {
  std::optional<std::string> value;
  for (const PlacedOption& option : options)
    if (option.files_before <= file_index) value = option.value;
  if (!value && !options.empty()) value = options.front().value;
  return value;
}

Result<std::string> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot read '" + path + "'");
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::string base_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

int run_fit_material_command(const std::vector<std::string>& args) {
  const std::string command = "fit-material";
  if (args.empty()) {
    std::fputs(HELP, stdout);
    return EXIT_BAD_INPUT;
  }
  // First pass: pull out the per-file options (--test, --radius, --thickness) with their positions, and
  // hand everything else to the common parser.
  std::vector<OptionSpec> specs = connection_option_specs();
  specs.push_back({"model"});
  specs.push_back({"name"});
  specs.push_back({"plot"});
  specs.push_back({"json", false});
  specs.push_back({"help", false});
  std::vector<PlacedOption> tests, radii, thicknesses;
  std::vector<std::string> rest;
  size_t files = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    std::string name, value;
    bool placed = false;
    for (const char* option : {"--test", "--radius", "--thickness"}) {
      const std::string prefix = std::string(option) + "=";
      if (word == option) {
        if (i + 1 >= args.size()) return report_error(command, std::string(option) + " needs a value", EXIT_BAD_INPUT);
        name = option;
        value = args[++i];
        placed = true;
      } else if (word.rfind(prefix, 0) == 0) {
        name = option;
        value = word.substr(prefix.size());
        placed = true;
      }
    }
    if (placed) {
      (name == "--test" ? tests : name == "--radius" ? radii : thicknesses).push_back({files, value});
      continue;
    }
    rest.push_back(word);
    if (word.rfind("--", 0) == 0) {
      const std::string option = word.substr(2);
      for (const OptionSpec& spec : specs)
        if (spec.name == option && spec.takes_value && i + 1 < args.size()) rest.push_back(args[++i]);
    } else {
      ++files;
    }
  }
  Result<ParsedArgs> parsed = parse_args(rest, specs);
  if (!parsed) return report_error(command, parsed.error(), EXIT_BAD_INPUT);
  if (parsed->has("help")) {
    std::fputs(HELP, stdout);
    std::fputs(connection_help(), stdout);
    return EXIT_OK;
  }
  if (parsed->positionals.empty()) return report_error(command, "expected at least one DATA.csv file", EXIT_BAD_INPUT);
  if (!parsed->get("model")) return report_error(command, "missing --model (hart-smith, mooney-rivlin, neo-hookean or all)", EXIT_BAD_INPUT);
  if (tests.empty()) return report_error(command, "missing --test (bulge, uniaxial, equibiaxial or pure-shear)", EXIT_BAD_INPUT);
  if (auto plot = parsed->get("plot"); plot && plot->size() < 5)
    return report_error(command, "--plot needs an .svg file name", EXIT_BAD_INPUT);

  std::vector<jobs::FitDataFile> data;
  for (size_t f = 0; f < parsed->positionals.size(); ++f) {
    const std::string& path = parsed->positionals[f];
    Result<std::string> bytes = read_file(path);
    if (!bytes) return report_error(command, bytes.error(), EXIT_BAD_INPUT);
    jobs::FitDataFile file;
    file.label = base_name(path);
    file.csv_text = std::move(*bytes);
    file.test = *placed_value(tests, f);
    if (auto radius = placed_value(radii, f)) {
      Result<double> number = parse_number("--radius", *radius);
      if (!number) return report_error(command, number.error(), EXIT_BAD_INPUT);
      file.radius_mm = *number;
    }
    if (auto thickness = placed_value(thicknesses, f)) {
      Result<double> number = parse_number("--thickness", *thickness);
      if (!number) return report_error(command, number.error(), EXIT_BAD_INPUT);
      file.thickness_mm = *number;
    }
    data.push_back(std::move(file));
  }
  Result<jobs::FitInput> input = jobs::prepare_fit(data, *parsed->get("model"));
  if (!input) return report_error(command, input.error(), EXIT_BAD_INPUT);
  // The fit runs as a service job (embedded server by default); the local checks above give bad data
  // its one-line error before anything connects.
  auto connection = ServiceConnection::open(connection_options(*parsed));
  if (!connection) return report_error(command, connection.error(), EXIT_UNAVAILABLE);
  v1::SubmitJobRequest request;
  v1::FitMaterialJob* job = request.mutable_spec()->mutable_fit_material();
  for (const jobs::FitDataFile& file : data) {
    v1::MeasurementSet* set = job->add_data();
    set->set_csv(file.csv_text);
    set->set_test(file.test);
    set->set_radius_mm(file.radius_mm);
    set->set_thickness_mm(file.thickness_mm);
    set->set_label(file.label);
  }
  job->set_model(*parsed->get("model"));
  const std::optional<std::string> name = parsed->get("name");
  if (name) job->set_name(*name);
  std::string job_id;
  {
    v1::SubmitJobResponse submitted;
    const grpc::Status status = (*connection)->submit(request, &submitted);
    if (!status.ok()) {
      std::string message = status.error_message();
      if (status.error_code() == grpc::StatusCode::PERMISSION_DENIED && name) message = "--name " + *name + ": " + message;
      return report_error(command, message, exit_code_for(status));
    }
    job_id = submitted.job().id();
  }
  const WatchOutcome watched = watch_job(**connection, job_id, [](const v1::JobEvent&) {});
  if (watched.interrupted) {
    cancel_job(**connection, job_id);
    return report_error(command, "interrupted; job " + job_id + " cancelled", EXIT_INTERRUPTED);
  }
  if (!watched.status.ok()) return report_error(command, watched.status.error_message(), exit_code_for(watched.status));
  if (watched.state != v1::JOB_STATE_COMPLETED) {
    // A fit fails on its data (exit 2, as when it ran in-process) unless the job was stopped from outside.
    const bool stopped = watched.state == v1::JOB_STATE_CANCELLED || watched.message.rfind("time limit", 0) == 0;
    return report_error(command, watched.message, stopped ? EXIT_JOB_FAILED : EXIT_BAD_INPUT);
  }
  v1::JobResult result;
  v1::Job finished;
  {
    grpc::ClientContext context;
    (*connection)->prepare(context);
    v1::GetResultRequest result_request;
    result_request.set_job_id(job_id);
    const grpc::Status status = (*connection)->stub().GetResult(&context, result_request, &result);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    grpc::ClientContext job_context;
    (*connection)->prepare(job_context);
    v1::GetJobRequest job_request;
    job_request.set_job_id(job_id);
    if (!(*connection)->stub().GetJob(&job_context, job_request, &finished).ok()) finished.Clear();
  }
  // The report carries every number; labels and tests come from the local input.
  Result<jobs::FitOutcome> outcome = jobs::fit_outcome_from_json(*input, result.report_json());
  if (!outcome) return report_error(command, "job " + job_id + ": " + outcome.error(), EXIT_INTERNAL);
  if (finished.finished_ms() > 0 && finished.started_ms() > 0)
    outcome->time_s = 1e-3 * static_cast<double>(finished.finished_ms() - finished.started_ms());

  if (auto plot = parsed->get("plot")) {
    Result<bool> written = write_file_atomically(*plot, jobs::fit_plot_svg(*input, *outcome));
    if (!written) return report_error(command, written.error(), EXIT_INTERNAL);
  }
  if (name && !parsed->has("json")) {
    const FitResult& best = outcome->fits[static_cast<size_t>(jobs::best_fit_index(*outcome))];
    std::printf("stored %s: %s\n", name->c_str(), material_spec(best.material).c_str());
  }
  if (parsed->has("json"))
    std::cout << jobs::fit_report_json(*input, *outcome) << std::endl;
  else
    std::cout << jobs::fit_summary_text(*input, *outcome);
  return EXIT_OK;
}

}  // namespace balloon::cli
