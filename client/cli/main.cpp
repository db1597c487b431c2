/// `balloon`: the command-line client. Dispatches to one subcommand per first word.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"

namespace {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>&);
};

const Command COMMANDS[] = {
    {"simulate", "inflate a rest mesh to equilibrium under a pressure or to a volume ratio",
     balloon::cli::run_simulate_command},
    {"design", "find the rest shape whose inflation matches a target; writes rest, inflated, mold, report",
     balloon::cli::run_design_command},
    {"submit", "queue a simulate job and print its id", balloon::cli::run_submit_command},
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
      "Usage: balloon <command> [options]    (balloon <command> --help for details)\n\n"
      "Commands:\n");
  for (const Command& command : COMMANDS) std::printf("  %-10s %s\n", command.name, command.summary);
  std::printf(
      "\nService: every command but `mesh` runs through the balloon service: an embedded in-process server\n"
      "on a local SQLite file by default ($XDG_DATA_HOME/balloon/balloon.db, --db overrides), or a remote\n"
      "balloon-server with --server HOST:PORT (env BALLOON_SERVER) and --token (env BALLOON_TOKEN).\n"
      "\nUnits: lengths mm, moduli MPa, pressure kPa, volumes mm^3, times s.\n"
      "Materials (SPEC): neo-hookean:mu=0.3 | mooney-rivlin:C1=0.18,C2=0.02 |\n"
      "                  hart-smith:G=0.1,k1=3e-4,k2=1.0 | a preset name (silicone, latex)\n\n%s",
      balloon::cli::EXIT_CODE_HELP);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    print_usage();
    return balloon::cli::EXIT_BAD_INPUT;
  }
  const std::string& name = args.front();
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage();
    return balloon::cli::EXIT_OK;
  }
  for (const Command& command : COMMANDS) {
    if (name != command.name) continue;
    try {
      return command.run(std::vector<std::string>(args.begin() + 1, args.end()));
    } catch (const std::exception& error) {
      return balloon::cli::report_error(name, std::string("internal error: ") + error.what(),
                                        balloon::cli::EXIT_INTERNAL);
    }
  }
  return balloon::cli::report_error("", "unknown command '" + name + "' (see balloon --help)",
                                    balloon::cli::EXIT_BAD_INPUT);
}
