#pragma once
/// The `balloon` subcommands. Each takes the words after its name (the global flags taken out, wherever
/// they stood) and the global flags, and returns a process exit code (exit_codes.hpp); each prints its
/// own help on --help.
#include <string>

#include "balloon/v1/balloon.pb.h"
#include <vector>

#include "global_options.hpp"

namespace balloon::cli {

/// `balloon simulate REST_MESH --material SPEC [--thickness MM] (--pressure KPA | --volume-ratio R)
/// [--out FILE] [--detach]`
int run_simulate_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon design TARGET_MESH --material SPEC [--thickness MM] [--size MM] [--resolution N]
/// [--scale S | --volume-ratio R] [--method adjoint|alm] [--nozzle ...] [--max-time S]
/// [--tolerance-samples N] [--out-dir DIR] [--detach]`: submit + watch + result of a design job.
int run_design_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon mesh sphere --radius MM --subdivisions K --out FILE`
int run_mesh_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon submit design|simulate|fit-material ARGS...`: queue a job of that kind, print its id.
int run_submit_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon jobs list|show|watch|cancel|result`
int run_jobs_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon materials list|show|delete|put`
int run_materials_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// `balloon fit-material DATA.csv ... --model M --test T [--radius MM --thickness MM] [--name N] [--plot F]`
int run_fit_material_command(const std::vector<std::string>& args, const GlobalOptions& global);

/// The human summary of a design report; `out_dir` empty leaves out the "written to" line.
std::string design_summary(const balloon::v1::DesignReport& report, const std::string& out_dir);
/// The human summary of a simulate report.
std::string simulate_summary(const balloon::v1::SimulateReport& report);
/// The human summary of a pressure-volume curve (a curve job): its points, extrema and stop reason.
std::string curve_summary(const balloon::v1::CurveReport& report);

}  // namespace balloon::cli
