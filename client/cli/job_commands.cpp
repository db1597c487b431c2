/// `balloon submit` and `balloon jobs list|show|watch|cancel|delete|result`: the job queue from the command line.
#include <google/protobuf/util/json_util.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "contract/job_result_files.hpp"
#include "exit_codes.hpp"
#include "job_watch.hpp"
#include "service_connection.hpp"
#include "global_options.hpp"
#include "job_command.hpp"
#include "result_files.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* SUBMIT_HELP =
    "Usage: balloon submit design TARGET_MESH ...    (the arguments of `balloon design`)\n"
    "       balloon submit simulate REST_MESH ...    (the arguments of `balloon simulate`)\n"
    "       balloon submit fit-material DATA.csv ... (the arguments of `balloon fit-material`)\n\n"
    "Queues a job and prints its id (--json: the job as JSON) without waiting for it: the same as the\n"
    "command with --detach. `balloon submit REST_MESH ...` without a kind queues a simulate job.\n"
    "Then: balloon jobs list | jobs watch ID (progress, then the summary) | jobs result ID --out-dir DIR\n"
    "(the files the command writes). `balloon submit KIND --help` lists the kind's options.\n\n"
    "With the embedded server (no --server) the job waits in the local store until a command that runs\n"
    "jobs starts: `balloon jobs watch ID` runs it and follows it.\n\n";

constexpr const char* JOBS_HELP =
    "Usage: balloon jobs list [--state STATE] [--limit N] [--json]\n"
    "       balloon jobs show ID [--json]\n"
    "       balloon jobs watch ID [--cancel-on-interrupt] [--json]\n"
    "       balloon jobs cancel ID [--json]\n"
    "       balloon jobs delete ID\n"
    "       balloon jobs result ID --out-dir DIR [--format obj|stl|ply] [--json]\n\n"
    "  list     your jobs, newest first; STATE: queued, running, completed, failed, cancelled\n"
    "  show     one job: state, summary, progress, timestamps\n"
    "  watch    re-attach to a job: its progress on stderr (the design's bar for a design) until it ends,\n"
    "           then its summary on stdout (--json: one event per line on stdout). Ctrl-C stops watching\n"
    "           and leaves the job running (--cancel-on-interrupt, or a second Ctrl-C, cancels it).\n"
    "           With the embedded server (no --server) this also runs the job: a job left queued or\n"
    "           interrupted in the local store runs again (a design from its last checkpoint) and is followed\n"
    "  cancel   cancel a queued or running job\n"
    "  delete   delete a finished job and its result (cancel a queued or running one first)\n"
    "  result   write a completed job's files into DIR, the same files its command writes:\n"
    "           design: rest.obj, inflated.obj, mold.stl, report.json, convergence.csv;\n"
    "           simulate: rest.obj, inflated.obj, report.json; fit-material: report.json, fit.svg\n"
    "           (--format stl|ply writes the meshes in that format instead)\n\n"
    "Exit codes: 0 ok, 2 bad input, 3 (watch/result) finished without converging, 4 no such job,\n"
    "5 unreachable, 6 not allowed, 7 no result yet, 8 the job failed or was cancelled, 130 Ctrl-C.\n\n";

std::string format_time(std::int64_t ms) {
  if (ms == 0) return "-";
  const std::time_t seconds = static_cast<std::time_t>(ms / 1000);
  std::tm local{};
  localtime_r(&seconds, &local);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%d %H:%M:%S", &local);
  return buffer;
}

void print_job(const v1::Job& job) {
  std::cout << job.id() << "  " << state_name(job.state());
  if (job.state() == v1::JOB_STATE_COMPLETED) std::cout << (job.converged() ? " (converged)" : " (not converged)");
  std::cout << "\n  " << job.summary() << "\n";
  std::cout << "  submitted " << format_time(job.created_ms()) << ", started " << format_time(job.started_ms())
            << ", finished " << format_time(job.finished_ms()) << ", attempts " << job.attempts() << "\n";
  if (job.state() == v1::JOB_STATE_QUEUED) std::cout << "  queue position " << job.queue_position() << "\n";
  if (job.has_last_progress()) {
    const auto& p = job.last_progress();
    std::cout << "  progress: " << p.phase() << " " << p.iteration() << ", " << format("%.2f", p.elapsed_s()) << " s, p=" << p.pressure_kpa()
              << " kPa, residual " << p.residual_norm() << " N\n";
  }
  if (!job.error().empty()) std::cout << "  " << job.error() << "\n";
}

int write_result(ServiceConnection& connection, const std::string& job_id, const ParsedArgs& parsed, bool json) {
  const char* command = "jobs result";
  const auto out_dir = parsed.get("out-dir");
  if (!out_dir) return report_error(command, "missing --out-dir DIR", EXIT_BAD_INPUT);
  const std::string extension = parsed.get("format").value_or("obj");
  const v1::MeshFormat format = mesh_format_from_path("x." + extension);
  if (format != v1::MESH_FORMAT_OBJ && format != v1::MESH_FORMAT_STL && format != v1::MESH_FORMAT_PLY)
    return report_error(command, "--format must be obj, stl or ply", EXIT_BAD_INPUT);
  grpc::Status status;
  Result<v1::JobResult> result = fetch_result(connection, job_id, format, &status);
  if (!result) return report_error(command, result.error(), exit_code_for(status));
  if (const std::string problem = output_directory_problem(*out_dir); !problem.empty())
    return report_error(command, problem, EXIT_BAD_INPUT);
  Result<std::vector<std::string>> written = write_result_files(*result, *out_dir);
  if (!written) return report_error(command, written.error(), EXIT_INTERNAL);
  if (json) {
    std::cout << contract::result_report_json(*result) << std::flush;
  } else {
    std::cout << "wrote";
    for (std::size_t i = 0; i < written->size(); ++i) std::cout << (i == 0 ? " " : ", ") << (*written)[i];
    std::cout << std::endl;
  }
  return result->converged() ? EXIT_OK : EXIT_NOT_CONVERGED;
}

/// `jobs watch`: re-attach with the kind's progress display, then print the summary of the result.
int watch(ServiceConnection& service, const std::string& job_id, const ParsedArgs& parsed, const GlobalOptions& global) {
  const std::string command = "jobs watch";
  v1::Job job;
  {
    grpc::ClientContext context;
    service.prepare(context);
    v1::GetJobRequest request;
    request.set_job_id(job_id);
    const grpc::Status status = service.stub().GetJob(&context, request, &job);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
  }
  const bool json = global.json;
  auto progress = job_progress(job.kind(), 0.0, false);
  InterruptPolicy policy;
  policy.cancel = parsed.has("cancel-on-interrupt");
  policy.connection = global.connection;
  const InterruptCatcher interrupts;
  const WatchOutcome outcome = watch_job(service, job_id, interrupts, [&](const v1::JobEvent& event) {
    if (!json) {
      progress(event);
      return;
    }
    v1::JobEvent light = event;  // positions would make lines megabytes long: counts only
    if (light.has_mesh()) {
      light.mutable_mesh()->clear_positions_mm();
      light.mutable_mesh()->clear_triangles();
    }
    std::cout << message_to_json(light) << std::endl;
  });
  progress = nullptr;  // ends an open progress line
  if (outcome.interrupted) return handle_interrupt(service, command, job_id, policy, interrupts);
  if (!outcome.status.ok()) return report_error(command, outcome.status.error_message(), exit_code_for(outcome.status));
  if (outcome.state != v1::JOB_STATE_COMPLETED) return EXIT_JOB_FAILED;
  if (!json && job.kind() != v1::JOB_KIND_FIT_MATERIAL) {
    grpc::Status status;
    Result<v1::JobResult> result = fetch_result(service, job_id, v1::MESH_FORMAT_OBJ, &status);
    if (!result) return report_error(command, result.error(), exit_code_for(status));
    std::cout << (job.kind() == v1::JOB_KIND_DESIGN  ? design_summary(result->design_report(), "")
                  : job.kind() == v1::JOB_KIND_CURVE ? curve_summary(result->curve_report())
                                                     : simulate_summary(result->simulate_report()))
              << std::flush;
    std::fprintf(stderr, "files: %s jobs result %s --out-dir DIR\n", command_prefix(global.connection).c_str(),
                 job_id.c_str());
  }
  return outcome.converged ? EXIT_OK : EXIT_NOT_CONVERGED;
}

}  // namespace

int run_submit_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  if (args.empty() || (global.help && args.front().rfind("-", 0) == 0)) {
    std::fputs(SUBMIT_HELP, stdout);
    std::fputs(job_options_help(), stdout);
    std::fputs(global_options_help(), stdout);
    return args.empty() && !global.help ? EXIT_BAD_INPUT : EXIT_OK;
  }
  for (const JobCommand* kind : {&design_job_command(), &simulate_job_command(), &fit_material_job_command()})
    if (args.front() == kind->name) return run_job_command(*kind, {args.begin() + 1, args.end()}, global, true);
  if (global.help) {
    std::fputs(SUBMIT_HELP, stdout);
    return EXIT_OK;
  }
  // `balloon submit REST_MESH ...`, the form before submit took a kind: a simulate job.
  return run_job_command(simulate_job_command(), args, global, true,
                         " (balloon submit without a kind queues a simulate job; a design: balloon submit design ...)");
}

int run_jobs_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  if (args.empty() || global.help) {
    std::fputs(JOBS_HELP, stdout);
    std::fputs(global_options_help(), stdout);
    return args.empty() && !global.help ? EXIT_BAD_INPUT : EXIT_OK;
  }
  const std::string action = args.front();
  const std::string command = "jobs " + action;
  if (action != "list" && action != "show" && action != "watch" && action != "cancel" && action != "delete" &&
      action != "result")
    return report_error("jobs", "unknown action '" + action + "' (list, show, watch, cancel, delete, result)",
                        EXIT_BAD_INPUT);
  std::vector<OptionSpec> specs;
  if (action == "list") specs = {{"state"}, {"limit"}};
  if (action == "watch") specs = {{"cancel-on-interrupt", false}};
  if (action == "result") specs = {{"out-dir"}, {"format"}};
  Result<ParsedArgs> parsed = parse_args({args.begin() + 1, args.end()}, specs);
  if (!parsed) return report_error(command, parsed.error(), EXIT_BAD_INPUT);
  const bool json = global.json;
  const bool needs_id = action != "list";
  if (needs_id && parsed->positionals.size() != 1) return report_error(command, "expected one job ID", EXIT_BAD_INPUT);
  if (!needs_id && !parsed->positionals.empty())
    return report_error(command, "unexpected argument '" + parsed->positionals.front() + "'", EXIT_BAD_INPUT);
  const std::string job_id = needs_id ? parsed->positionals.front() : "";

  ConnectionOptions options = global.connection;
  options.run_jobs = action == "watch";  // only watching waits for a job to run
  auto connection = ServiceConnection::open(options);
  if (!connection) return report_error(command, connection.error(), EXIT_UNAVAILABLE);
  ServiceConnection& service = **connection;

  if (action == "list") {
    v1::ListJobsRequest request;
    if (const auto state = parsed->get("state")) {
      bool known = false;
      for (v1::JobState candidate : {v1::JOB_STATE_QUEUED, v1::JOB_STATE_RUNNING, v1::JOB_STATE_COMPLETED,
                                     v1::JOB_STATE_FAILED, v1::JOB_STATE_CANCELLED})
        if (state_name(candidate) == *state) {
          request.set_state(candidate);
          known = true;
        }
      if (!known) return report_error(command, "--state must be queued, running, completed, failed or cancelled", EXIT_BAD_INPUT);
    }
    if (const auto limit = parsed->get("limit")) {
      Result<long long> n = parse_integer("limit", *limit, 1, 1000);
      if (!n) return report_error(command, n.error(), EXIT_BAD_INPUT);
      request.set_page_size(static_cast<int>(*n));
    }
    grpc::ClientContext context;
    service.prepare(context);
    v1::ListJobsResponse reply;
    const grpc::Status status = service.stub().ListJobs(&context, request, &reply);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    if (json) {
      std::cout << message_to_json(reply) << std::endl;
    } else {
      for (const v1::Job& job : reply.jobs())
        std::printf("%s  %-9s %s  %s\n", job.id().c_str(), state_name(job.state()).c_str(),
                    format_time(job.created_ms()).c_str(), job.summary().c_str());
      if (reply.jobs().empty()) std::printf("no jobs\n");
    }
    return EXIT_OK;
  }

  if (action == "delete") {
    grpc::ClientContext context;
    service.prepare(context);
    v1::DeleteJobRequest request;
    request.set_job_id(job_id);
    v1::DeleteJobResponse reply;
    const grpc::Status status = service.stub().DeleteJob(&context, request, &reply);
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    if (json)
      std::cout << "{\"deleted\":\"" << job_id << "\"}" << std::endl;
    else
      std::printf("deleted %s\n", job_id.c_str());
    return EXIT_OK;
  }

  if (action == "show" || action == "cancel") {
    grpc::ClientContext context;
    service.prepare(context);
    v1::Job job;
    grpc::Status status;
    if (action == "show") {
      v1::GetJobRequest request;
      request.set_job_id(job_id);
      status = service.stub().GetJob(&context, request, &job);
    } else {
      v1::CancelJobRequest request;
      request.set_job_id(job_id);
      status = service.stub().CancelJob(&context, request, &job);
    }
    if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
    if (json)
      std::cout << message_to_json(job) << std::endl;
    else
      print_job(job);
    return EXIT_OK;
  }

  if (action == "watch") return watch(service, job_id, *parsed, global);
  return write_result(service, job_id, *parsed, json);
}

}  // namespace balloon::cli
