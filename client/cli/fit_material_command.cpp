/// `balloon fit-material`: fit rubber laws to measurement files, print, plot, and optionally store the fit
/// in the service's material library. The fit itself runs in-process through the job layer
/// (server/jobs/fit_job), the same code the service's fit_material job is meant to call; only storing
/// (--name) talks to the service.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
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
  std::vector<std::string> labels;
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
    labels.push_back(path);
    data.push_back(std::move(file));
  }
  Result<jobs::FitInput> input = jobs::prepare_fit(data, *parsed->get("model"));
  if (!input) return report_error(command, input.error(), EXIT_BAD_INPUT);
  Result<jobs::FitOutcome> outcome = jobs::run_fit(*input);
  if (!outcome) return report_error(command, outcome.error(), EXIT_BAD_INPUT);

  if (auto plot = parsed->get("plot")) {
    Result<bool> written = write_file_atomically(*plot, jobs::fit_plot_svg(*input, *outcome));
    if (!written) return report_error(command, written.error(), EXIT_INTERNAL);
  }
  if (auto name = parsed->get("name")) {
    const FitResult& best = outcome->fits[static_cast<size_t>(jobs::best_fit_index(*outcome))];
    ConnectionOptions connection_opts = connection_options(*parsed);
    connection_opts.run_jobs = false;
    auto connection = ServiceConnection::open(connection_opts);
    if (!connection) return report_error(command, connection.error(), EXIT_UNAVAILABLE);
    grpc::ClientContext context;
    (*connection)->prepare(context);
    v1::PutMaterialRequest request;
    request.mutable_material()->set_name(*name);
    request.mutable_material()->set_spec(material_spec(best.material));
    request.mutable_material()->set_description(jobs::fit_provenance(*input, best, labels));
    v1::Material stored;
    const grpc::Status status = (*connection)->stub().PutMaterial(&context, request, &stored);
    if (!status.ok()) return report_error(command, "--name " + *name + ": " + status.error_message(), exit_code_for(status));
    if (!parsed->has("json")) std::printf("stored %s: %s\n", stored.name().c_str(), stored.spec().c_str());
  }
  if (parsed->has("json"))
    std::cout << jobs::fit_report_json(*input, *outcome) << std::endl;
  else
    std::cout << jobs::fit_summary_text(*input, *outcome);
  return EXIT_OK;
}

}  // namespace balloon::cli
