#pragma once
/// The one path of the commands that run a job (design, simulate, fit-material): parse and check the
/// arguments locally, submit, then either return at once (--detach, `balloon submit KIND`) or follow the
/// job with its progress and write its result. Each kind supplies its parts in a JobCommand.
#include <any>
#include <functional>
#include <string>
#include <vector>

#include "arg_parser.hpp"
#include "balloon/v1/balloon.pb.h"
#include "global_options.hpp"
#include "job_watch.hpp"
#include "result.hpp"
#include "service_connection.hpp"

namespace balloon::cli {

/// What a job command made of its arguments before any connection.
struct PreparedJob {
  balloon::v1::SubmitJobRequest request;
  ParsedArgs args;         ///< the command's own parsed options (its output flags, for `finish`)
  std::string file_field;  ///< path of the request field that carries the user's file ("design.target_mesh"), for errors
  std::string file_path;   ///< that file
  std::any context;        ///< what `finish` needs beyond the args (the fit's checked data)
};

/// One job-running command's parts.
struct JobCommand {
  const char* name;  ///< "design": the command, and the word after `balloon submit`
  const char* help;  ///< its --help text; the job and global options' help is appended
  std::vector<std::string> output_options;  ///< options only used when following ("out-dir")
  /// Parses the command's own arguments (global and job options already taken out) and checks them.
  Result<PreparedJob> (*prepare)(const std::vector<std::string>& args);
  /// Checks the output options before any work (empty: fine). Not called when detached.
  std::string (*check_outputs)(const PreparedJob& job);
  /// After COMPLETED: fetches the result, writes and prints it; returns the exit code.
  int (*finish)(ServiceConnection& connection, const PreparedJob& job, const std::string& job_id,
                const GlobalOptions& global);
  /// The exit code of a job that FAILED with `message`; null: EXIT_JOB_FAILED.
  int (*failed_exit_code)(const std::string& message) = nullptr;
};

/// `balloon design|simulate|fit-material ARGS...` (`detach` false; --detach in ARGS detaches) and
/// `balloon submit KIND ARGS...` (`detach` true): the same arguments, parsed by `command.prepare`.
/// `hint` is added to the errors in the command's own arguments.
int run_job_command(const JobCommand& command, const std::vector<std::string>& args, const GlobalOptions& global,
                    bool detach, const std::string& hint = "");

/// The help of the options every job command takes (--detach, --cancel-on-interrupt, --priority,
/// --time-limit) and of Ctrl-C.
const char* job_options_help();

/// Progress display for a job of `kind` on stderr: the design's bar (on a terminal; lines otherwise), or
/// the generic progress lines. `terminal_only`: print nothing unless stderr is a terminal (the commands
/// that also print a result), except the design, whose lines are always useful.
std::function<void(const balloon::v1::JobEvent&)> job_progress(balloon::v1::JobKind kind, double max_time_s,
                                                               bool terminal_only);

/// The three kinds.
const JobCommand& design_job_command();
const JobCommand& simulate_job_command();
const JobCommand& fit_material_job_command();

}  // namespace balloon::cli
