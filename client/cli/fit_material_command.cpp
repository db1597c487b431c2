/// `balloon fit-material`: fit rubber laws to measurement files, print, plot, and optionally store the fit
/// in the service's material library. The data are checked locally (server/jobs/fit_job), then the fit
/// runs as a fit_material job on the service (embedded by default), which also stores it under --name.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "cli_output.hpp"
#include "service/job_reports.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "job_command.hpp"
#include "job_watch.hpp"
#include "result_files.hpp"
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
    "  bulge data: columns pressure_kpa,extension_ratio[,apex_height_mm]; simulated as an axisymmetric clamped\n"
    "              membrane, at the apex heights when the file has them\n"
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

/// The fit's data as checked locally, and the --name to store it under: what `finish` needs.
struct FitContext {
  jobs::FitInput input;
};

Result<PreparedJob> prepare_fit_material(const std::vector<std::string>& args) {
  // First pass: pull out the per-file options (--test, --radius, --thickness) with their positions, and
  // hand everything else to the common parser.
  std::vector<OptionSpec> specs = {{"model"}, {"name"}, {"plot"}};
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
        if (i + 1 >= args.size()) return fail(std::string(option) + " needs a value");
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
  if (!parsed) return fail(parsed.error());
  if (parsed->positionals.empty()) return fail("expected at least one DATA.csv file (see --help)");
  if (!parsed->get("model")) return fail("missing --model (hart-smith, mooney-rivlin, neo-hookean or all)");
  if (tests.empty()) return fail("missing --test (bulge, uniaxial, equibiaxial or pure-shear)");
  if (auto plot = parsed->get("plot"); plot && plot->size() < 5) return fail("--plot needs an .svg file name");

  std::vector<jobs::FitDataFile> data;
  for (size_t f = 0; f < parsed->positionals.size(); ++f) {
    const std::string& path = parsed->positionals[f];
    Result<std::string> bytes = read_file(path);
    if (!bytes) return fail(bytes.error());
    jobs::FitDataFile file;
    file.label = base_name(path);
    file.csv_text = std::move(*bytes);
    file.test = *placed_value(tests, f);
    if (auto radius = placed_value(radii, f)) {
      Result<double> number = parse_number("--radius", *radius);
      if (!number) return fail(number.error());
      file.radius_mm = *number;
    }
    if (auto thickness = placed_value(thicknesses, f)) {
      Result<double> number = parse_number("--thickness", *thickness);
      if (!number) return fail(number.error());
      file.thickness_mm = *number;
    }
    data.push_back(std::move(file));
  }
  // The local checks give bad data its one-line error before anything connects.
  Result<jobs::FitInput> input = jobs::prepare_fit(data, *parsed->get("model"));
  if (!input) return fail(input.error());

  PreparedJob job;
  v1::FitMaterialJob* fit = job.request.mutable_spec()->mutable_fit_material();
  for (const jobs::FitDataFile& file : data) {
    v1::MeasurementSet* set = fit->add_data();
    set->set_csv(file.csv_text);
    set->set_test(file.test);
    set->set_radius_mm(file.radius_mm);
    set->set_thickness_mm(file.thickness_mm);
    set->set_label(file.label);
  }
  fit->set_model(*parsed->get("model"));
  if (const auto name = parsed->get("name")) fit->set_name(*name);
  job.args = std::move(*parsed);
  job.context = std::make_shared<const FitContext>(FitContext{std::move(*input)});
  return job;
}

std::string check_fit_outputs(const PreparedJob&) { return ""; }

/// A fit fails on its data (exit 2, as when it ran in-process) unless it was stopped from outside.
int fit_failed_exit_code(const std::string& message) {
  return message.rfind("time limit", 0) == 0 ? EXIT_JOB_FAILED : EXIT_BAD_INPUT;
}

int finish_fit_material(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                        const GlobalOptions& global) {
  const std::string command = "fit-material";
  const jobs::FitInput& input = std::any_cast<const std::shared_ptr<const FitContext>&>(job.context)->input;
  grpc::Status status;
  Result<v1::JobResult> result = fetch_result(connection, job_id, v1::MESH_FORMAT_UNSPECIFIED, &status);
  if (!result) return report_error(command, result.error(), exit_code_for(status));
  v1::Job finished;
  {
    grpc::ClientContext job_context;
    connection.prepare(job_context);
    v1::GetJobRequest job_request;
    job_request.set_job_id(job_id);
    if (!connection.stub().GetJob(&job_context, job_request, &finished).ok()) finished.Clear();
  }
  // The report carries every number; labels and tests come from the local input.
  Result<jobs::FitOutcome> outcome = service::fit_outcome_from_report(input, result->fit_report());
  if (!outcome) return report_error(command, "job " + job_id + ": " + outcome.error(), EXIT_INTERNAL);
  if (finished.finished_ms() > 0 && finished.started_ms() > 0)
    outcome->time_s = 1e-3 * static_cast<double>(finished.finished_ms() - finished.started_ms());

  if (auto plot = job.args.get("plot")) {
    Result<bool> written = write_file_atomically(*plot, jobs::fit_plot_svg(input, *outcome));
    if (!written) return report_error(command, written.error(), EXIT_INTERNAL);
  }
  const std::optional<std::string> name = job.args.get("name");
  if (name && !global.json) {
    const FitResult& best = outcome->fits[static_cast<size_t>(jobs::best_fit_index(*outcome))];
    std::printf("stored %s: %s\n", name->c_str(), material_spec(best.material).c_str());
  }
  if (global.json)
    std::cout << jobs::fit_report_json(input, *outcome) << std::endl;
  else
    std::cout << jobs::fit_summary_text(input, *outcome);
  return EXIT_OK;
}

}  // namespace

const JobCommand& fit_material_job_command() {
  static const JobCommand PARTS{"fit-material",       HELP, {"plot"}, prepare_fit_material, check_fit_outputs,
                                finish_fit_material, fit_failed_exit_code};
  return PARTS;
}

int run_fit_material_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  if (args.empty() && !global.help) {
    std::fputs(HELP, stdout);
    return EXIT_BAD_INPUT;
  }
  return run_job_command(fit_material_job_command(), args, global, false);
}

}  // namespace balloon::cli
