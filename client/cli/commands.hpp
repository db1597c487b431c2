#pragma once
/// The `balloon` subcommands. Each takes the words after its name and returns a process exit code
/// (exit_codes.hpp); each prints its own help on --help.
#include <string>
#include <vector>

namespace balloon::cli {

/// `balloon simulate REST_MESH --material SPEC [--thickness MM] (--pressure KPA | --volume-ratio R)
/// [--out FILE] [--json]`
int run_simulate_command(const std::vector<std::string>& args);

/// `balloon design TARGET_MESH --material SPEC [--thickness MM] [--size MM] [--resolution N]
/// [--scale S | --volume-ratio R] [--method adjoint|alm] [--nozzle ...] [--max-time S]
/// [--tolerance-samples N] [--out-dir DIR] [--json]`: submit + watch + result of a design job.
int run_design_command(const std::vector<std::string>& args);

/// `balloon mesh sphere --radius MM --subdivisions K --out FILE [--json]`
int run_mesh_command(const std::vector<std::string>& args);

/// `balloon submit REST_MESH ...`: queue a simulate job, print its id.
int run_submit_command(const std::vector<std::string>& args);

/// `balloon jobs list|show|watch|cancel|result`
int run_jobs_command(const std::vector<std::string>& args);

/// `balloon materials list|show|delete|put`
int run_materials_command(const std::vector<std::string>& args);

/// `balloon fit-material DATA.csv ... --model M --test T [--radius MM --thickness MM] [--name N] [--plot F] [--json]`
int run_fit_material_command(const std::vector<std::string>& args);

}  // namespace balloon::cli
