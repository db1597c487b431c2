#include "job_command.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "cli_output.hpp"
#include "design_progress.hpp"
#include "exit_codes.hpp"
#include "field_flags.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

/// The options of every job command, found before or after its own (as the global ones are).
const std::vector<OptionSpec>& job_option_specs() {
  static const std::vector<OptionSpec> SPECS = {
      {"detach", false}, {"cancel-on-interrupt", false}, {"priority"}, {"time-limit"}};
  return SPECS;
}

/// --priority and --time-limit into the request's spec.
std::string apply_job_options(const ParsedArgs& options, v1::SubmitJobRequest& request) {
  if (const auto text = options.get("priority")) {
    Result<long long> priority = parse_integer("priority", *text, -100, 100);
    if (!priority) return priority.error();
    request.mutable_spec()->set_priority(static_cast<int>(*priority));
  }
  if (const auto text = options.get("time-limit")) {
    Result<double> limit = parse_number("time-limit", *text);
    if (!limit) return limit.error();
    if (*limit <= 0.0) return "--time-limit must be positive (s)";
    request.mutable_spec()->set_time_limit_s(*limit);
  }
  return "";
}

}  // namespace

const char* job_options_help() {
  return "Job options (every job command, and `balloon submit KIND`):\n"
         "  --detach               queue the job, print its id (--json: the job) and return at once;\n"
         "                         `balloon submit KIND ARGS` is the same as `balloon KIND ARGS --detach`\n"
         "  --cancel-on-interrupt  Ctrl-C cancels the job instead of detaching from it\n"
         "  --priority P           -100..100, higher runs first (default 0)\n"
         "  --time-limit S         wall-time limit in seconds (default: the server's); a design, a\n"
         "                         simulation or a curve stops before it and keeps what it reached (the\n"
         "                         best design, the last equilibrium, the points so far); a fit fails at it\n"
         "Ctrl-C while following a job detaches: the job keeps running on the --server (or, with the\n"
         "embedded server, stays in the local store and runs again when resumed), the id and the command\n"
         "that resumes it (balloon [--server HOST:PORT] jobs watch ID) are printed, and the exit code is\n"
         "130. A second Ctrl-C within a second cancels the job. `balloon jobs result ID --out-dir DIR`\n"
         "writes the files of a finished job.\n";
}

std::function<void(const v1::JobEvent&)> job_progress(v1::JobKind kind, double max_time_s, bool terminal_only) {
  const bool terminal = isatty(STDERR_FILENO) == 1;
  if (kind == v1::JOB_KIND_DESIGN) {
    auto bar = std::make_shared<DesignProgress>(terminal, max_time_s);
    return [bar](const v1::JobEvent& event) { (*bar)(event); };
  }
  if (kind == v1::JOB_KIND_FIT_MATERIAL && terminal_only) return [](const v1::JobEvent&) {};
  auto printer = std::make_shared<ProgressPrinter>(terminal || !terminal_only);
  return [printer](const v1::JobEvent& event) { (*printer)(event); };
}

int run_job_command(const JobCommand& command, const std::vector<std::string>& args, const GlobalOptions& global,
                    bool detach, const std::string& hint) {
  const std::string name = detach ? std::string("submit ") + command.name : command.name;
  if (global.help) {
    std::fputs(command.help, stdout);
    std::fputs(job_options_help(), stdout);
    std::fputs(global_options_help(), stdout);
    return EXIT_OK;
  }
  std::vector<std::string> own;
  Result<ParsedArgs> job_options = take_options(args, job_option_specs(), &own);
  if (!job_options) return report_error(name, job_options.error(), EXIT_BAD_INPUT);
  detach = detach || job_options->has("detach");
  if (detach && job_options->has("cancel-on-interrupt"))
    return report_error(name, "--cancel-on-interrupt has no use with --detach (nothing is followed)", EXIT_BAD_INPUT);

  // Every local check comes before any connection, so the cheapest problems are reported first.
  Result<PreparedJob> prepared = command.prepare(own);
  if (!prepared) return report_error(name, prepared.error() + hint, EXIT_BAD_INPUT);
  if (const std::string problem = apply_job_options(*job_options, prepared->request); !problem.empty())
    return report_error(name, problem, EXIT_BAD_INPUT);
  if (!detach) {
    if (const std::string problem = command.check_outputs(*prepared); !problem.empty())
      return report_error(name, problem, EXIT_BAD_INPUT);
  }

  // Caught from before the submit: a Ctrl-C while it is under way detaches once the id is known.
  std::optional<InterruptCatcher> interrupts;
  if (!detach) interrupts.emplace();
  ConnectionOptions connection_options = global.connection;
  connection_options.run_jobs = !detach;  // a detached job waits in the embedded store for `jobs watch`
  // This command's job runs now, not after jobs that killed commands left in the embedded store.
  connection_options.run_recovered = false;
  auto connection = ServiceConnection::open(connection_options);
  if (!connection) return report_error(name, connection.error(), EXIT_UNAVAILABLE);

  v1::SubmitJobResponse submitted;
  if (const grpc::Status status = (*connection)->submit(prepared->request, &submitted); !status.ok())
    return report_error(name, message_naming_fields(status, prepared->file_field, prepared->file_path),
                        exit_code_for(status));
  const std::string job_id = submitted.job().id();

  if (detach) {
    for (const std::string& option : command.output_options)
      if (prepared->args.has(option))
        std::fprintf(stderr, "balloon %s: note: --%s is not used by a detached job; `balloon jobs result %s` writes the result\n",
                     name.c_str(), option.c_str(), job_id.c_str());
    if (global.json)
      std::cout << message_to_json(submitted.job()) << std::endl;
    else
      std::cout << job_id << std::endl;
    return EXIT_OK;
  }

  const v1::JobSpec& spec = prepared->request.spec();
  const double max_time_s = spec.has_design() ? spec.design().max_time_s() : 0.0;
  auto progress = job_progress(submitted.job().kind(), max_time_s, true);
  InterruptPolicy policy;
  policy.cancel = job_options->has("cancel-on-interrupt");
  policy.connection = global.connection;
  {
    const WatchOutcome outcome = watch_job(**connection, job_id, *interrupts, progress);
    if (outcome.interrupted) return handle_interrupt(**connection, name, job_id, policy, *interrupts);
    if (!outcome.status.ok()) return report_error(name, outcome.status.error_message(), exit_code_for(outcome.status));
    if (outcome.state == v1::JOB_STATE_FAILED && command.failed_exit_code != nullptr)
      return report_error(name, outcome.message, command.failed_exit_code(outcome.message));
    if (outcome.state != v1::JOB_STATE_COMPLETED)
      return report_error(name, "job " + job_id + " " + state_name(outcome.state) + ": " + outcome.message,
                          EXIT_JOB_FAILED);
  }
  progress = nullptr;  // ends an open progress line before the result is printed
  return command.finish(**connection, *prepared, job_id, global);
}

}  // namespace balloon::cli
