/// `balloon`: the command-line client. Takes the global flags out wherever they stand, then dispatches
/// to one subcommand per first remaining word.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "global_options.hpp"

namespace {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>&, const balloon::cli::GlobalOptions&);
};

const Command COMMANDS[] = {
    {"simulate", "inflate a rest mesh to equilibrium under a pressure or to a volume ratio",
     balloon::cli::run_simulate_command},
    {"design", "find the rest shape whose inflation matches a target; writes rest, inflated, mold, report",
     balloon::cli::run_design_command},
    {"submit", "queue a design, simulate or fit-material job and print its id (= the command with --detach)",
     balloon::cli::run_submit_command},
    {"jobs", "list, show, watch, cancel jobs and fetch results", balloon::cli::run_jobs_command},
    {"materials", "list, show, delete and store materials", balloon::cli::run_materials_command},
    {"fit-material", "fit rubber laws to measurements (bulge or stress tables); --name stores the fit",
     balloon::cli::run_fit_material_command},
    {"mesh", "make meshes (`balloon mesh sphere --radius MM --subdivisions K --out FILE`)",
     balloon::cli::run_mesh_command},
};

void print_usage() {
  std::printf(
      "balloon: design and simulate rubber balloons\n\n"
      "Usage: balloon [global options] <command> [options]    (balloon <command> --help for details)\n\n"
      "Commands:\n");
  for (const Command& command : COMMANDS) std::printf("  %-13s %s\n", command.name, command.summary);
  std::printf(
      "\nService: every command but `mesh` runs through the balloon service: an embedded in-process server\n"
      "on a local SQLite file by default ($XDG_DATA_HOME/balloon/balloon.db, --db overrides), or a remote\n"
      "balloon-server with --server HOST:PORT (env BALLOON_SERVER) and --token (env BALLOON_TOKEN).\n"
      "\nRemote work, fire and forget:\n"
      "  balloon --server HOST:PORT submit design TARGET_MESH --material SPEC ...   prints the job id\n"
      "  balloon --server HOST:PORT jobs list\n"
      "  balloon --server HOST:PORT jobs watch ID                 progress, then the summary\n"
      "  balloon --server HOST:PORT jobs result ID --out-dir DIR  the files `balloon design` writes\n"
      "Ctrl-C while a command follows its job detaches (the job keeps running; the resume command is\n"
      "printed; exit 130); --cancel-on-interrupt or a second Ctrl-C cancels it.\n\n");
  std::fputs(balloon::cli::global_options_help(), stdout);
  std::printf(
      "\nUnits: lengths mm, moduli MPa, pressure kPa, volumes mm^3, times s.\n"
      "Materials (SPEC): neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
      "                  hart-smith:G=0.1,k1=3e-4,k2=1.0 | a preset name (silicone, latex)\n\n%s",
      balloon::cli::EXIT_CODE_HELP);
}

}  // namespace

int main(int argc, char** argv) {
  const balloon::Result<balloon::cli::SplitCommandLine> split =
      balloon::cli::split_global_options(std::vector<std::string>(argv + 1, argv + argc));
  if (!split) return balloon::cli::report_error("", split.error(), balloon::cli::EXIT_BAD_INPUT);
  const std::vector<std::string>& words = split->words;
  const balloon::cli::GlobalOptions& global = split->global;
  if (words.empty() || words.front() == "help") {
    print_usage();
    return words.empty() && !global.help ? balloon::cli::EXIT_BAD_INPUT : balloon::cli::EXIT_OK;
  }
  const std::string& name = words.front();
  for (const Command& command : COMMANDS) {
    if (name != command.name) continue;
    try {
      return command.run(std::vector<std::string>(words.begin() + 1, words.end()), global);
    } catch (const std::exception& error) {
      return balloon::cli::report_error(name, std::string("internal error: ") + error.what(),
                                        balloon::cli::EXIT_INTERNAL);
    }
  }
  return balloon::cli::report_error("", "unknown command '" + name + "' (see balloon --help)",
                                    balloon::cli::EXIT_BAD_INPUT);
}
