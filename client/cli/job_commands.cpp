/// `balloon submit` and `balloon jobs list|show|watch|cancel|delete|result`: the job queue from the command line.
#include <google/protobuf/util/json_util.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "job_watch.hpp"
#include "service_connection.hpp"
#include "simulate_request.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;

constexpr const char* SUBMIT_HELP =
    "Usage: balloon submit REST_MESH --material SPEC [--thickness MM] (--pressure KPA | --volume-ratio R)\n"
    "                      [--priority P] [--time-limit S] [--json]\n\n"
    "Queues a simulate job and prints its id (design jobs arrive with `balloon design`). Options as for\n"
    "`balloon simulate`, plus:\n"
    "  --priority P     -100..100, higher runs first (default 0)\n"
    "  --time-limit S   wall-time limit in seconds (default: the server's)\n"
    "  --json           print the job as JSON\n\n"
    "With the embedded server the job waits in the local store until a command that runs jobs (balloon\n"
    "jobs watch ID, balloon simulate) starts one.\n\n";

constexpr const char* JOBS_HELP =
    "Usage: balloon jobs list [--state STATE] [--limit N] [--json]\n"
    "       balloon jobs show ID [--json]\n"
    "       balloon jobs watch ID [--json]\n"
    "       balloon jobs cancel ID [--json]\n"
    "       balloon jobs delete ID\n"
    "       balloon jobs result ID --out-dir DIR [--format obj|stl|ply] [--json]\n\n"
    "  list     your jobs, newest first; STATE: queued, running, completed, failed, cancelled\n"
    "  show     one job: state, summary, progress, timestamps\n"
    "  watch    follow a job until it ends (progress on stderr; --json: one event per line on stdout).\n"
    "           Ctrl-C stops watching and leaves the job running\n"
    "  cancel   cancel a queued or running job\n"
    "  delete   delete a finished job and its result (cancel a queued or running one first)\n"
    "  result   write rest.EXT, inflated.EXT and report.json of a completed job into DIR\n\n"
    "Exit codes: 0 ok, 2 bad input, 3 (watch/result) finished without converging, 4 no such job,\n"
    "5 unreachable, 6 not allowed, 7 no result yet, 8 the job failed or was cancelled, 130 Ctrl-C.\n\n";

std::string to_json(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

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
    std::cout << "  progress: " << p.phase() << " " << p.iteration() << ", " << p.elapsed_s() << " s, p=" << p.pressure_kpa()
              << " kPa, residual " << p.residual_norm() << " N\n";
  }
  if (!job.error().empty()) std::cout << "  " << job.error() << "\n";
}

/// Parses args with the connection options plus `extra`; prints help on --help.
Result<ParsedArgs> parse_with_connection(const std::vector<std::string>& args, std::vector<OptionSpec> extra) {
  for (const OptionSpec& spec : connection_option_specs()) extra.push_back(spec);
  extra.push_back({"json", false});
  extra.push_back({"help", false});
  return parse_args(args, extra);
}

int submit(const std::vector<std::string>& args) {
  const char* command = "submit";
  std::vector<OptionSpec> extra = simulate_option_specs();
  extra.push_back({"priority"});
  extra.push_back({"time-limit"});
  Result<ParsedArgs> parsed = parse_with_connection(args, extra);
  if (!parsed) return report_error(command, parsed.error(), EXIT_BAD_INPUT);
  if (parsed->has("help")) {
    std::fputs(SUBMIT_HELP, stdout);
    std::fputs(connection_help(), stdout);
    return EXIT_OK;
  }
  Result<v1::SubmitJobRequest> request = simulate_request_from_args(*parsed);
  if (!request) return report_error(command, request.error(), EXIT_BAD_INPUT);
  if (const auto text = parsed->get("priority")) {
    Result<long long> priority = parse_integer("priority", *text, -100, 100);
    if (!priority) return report_error(command, priority.error(), EXIT_BAD_INPUT);
    request->mutable_spec()->set_priority(static_cast<int>(*priority));
  }
  if (const auto text = parsed->get("time-limit")) {
    Result<double> limit = parse_number("time-limit", *text);
    if (!limit || *limit <= 0.0)
      return report_error(command, limit ? "--time-limit must be positive (s)" : limit.error(), EXIT_BAD_INPUT);
    request->mutable_spec()->set_time_limit_s(*limit);
  }
  ConnectionOptions options = connection_options(*parsed);
  options.run_jobs = false;
  auto connection = ServiceConnection::open(options);
  if (!connection) return report_error(command, connection.error(), EXIT_UNAVAILABLE);
  v1::SubmitJobResponse reply;
  const grpc::Status status = (*connection)->submit(*request, &reply);
  if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
  if (parsed->has("json"))
    std::cout << to_json(reply.job()) << std::endl;
  else
    std::cout << reply.job().id() << std::endl;
  return EXIT_OK;
}

int write_result(ServiceConnection& connection, const std::string& job_id, const ParsedArgs& parsed) {
  const char* command = "jobs result";
  const auto out_dir = parsed.get("out-dir");
  if (!out_dir) return report_error(command, "missing --out-dir DIR", EXIT_BAD_INPUT);
  const std::string extension = parsed.get("format").value_or("obj");
  const v1::MeshFormat format = mesh_format_from_path("x." + extension);
  if (format != v1::MESH_FORMAT_OBJ && format != v1::MESH_FORMAT_STL && format != v1::MESH_FORMAT_PLY)
    return report_error(command, "--format must be obj, stl or ply", EXIT_BAD_INPUT);
  v1::GetResultRequest request;
  request.set_job_id(job_id);
  request.set_format(format);
  v1::JobResult result;
  grpc::ClientContext context;
  connection.prepare(context);
  const grpc::Status status = connection.stub().GetResult(&context, request, &result);
  if (!status.ok()) return report_error(command, status.error_message(), exit_code_for(status));
  std::error_code error;
  std::filesystem::create_directories(*out_dir, error);
  if (error) return report_error(command, "cannot create '" + *out_dir + "': " + error.message(), EXIT_INTERNAL);
  const std::filesystem::path dir(*out_dir);
  for (const auto& [name, bytes] : {std::pair<std::string, const std::string*>{"rest." + extension, &result.rest_mesh().data()},
                                    {"inflated." + extension, &result.inflated_mesh().data()},
                                    {"report.json", &result.report_json()}}) {
    Result<bool> written = write_file_atomically((dir / name).string(), *bytes + (name == "report.json" ? "\n" : ""));
    if (!written) return report_error(command, written.error(), EXIT_INTERNAL);
  }
  if (parsed.has("json"))
    std::cout << result.report_json() << std::endl;
  else
    std::cout << "wrote " << (dir / ("rest." + extension)).string() << ", " << (dir / ("inflated." + extension)).string()
              << ", " << (dir / "report.json").string() << std::endl;
  return result.converged() ? EXIT_OK : EXIT_NOT_CONVERGED;
}

}  // namespace

int run_submit_command(const std::vector<std::string>& args) { return submit(args); }

int run_jobs_command(const std::vector<std::string>& args) {
  if (args.empty() || args.front() == "--help" || args.front() == "-h") {
    std::fputs(JOBS_HELP, stdout);
    std::fputs(connection_help(), stdout);
    return args.empty() ? EXIT_BAD_INPUT : EXIT_OK;
  }
  const std::string action = args.front();
  const std::string command = "jobs " + action;
  Result<ParsedArgs> parsed =
      parse_with_connection({args.begin() + 1, args.end()}, {{"state"}, {"limit"}, {"out-dir"}, {"format"}});
  if (!parsed) return report_error(command, parsed.error(), EXIT_BAD_INPUT);
  if (parsed->has("help")) {
    std::fputs(JOBS_HELP, stdout);
    std::fputs(connection_help(), stdout);
    return EXIT_OK;
  }
  const bool json = parsed->has("json");
  const bool needs_id = action != "list";
  if (action != "list" && action != "show" && action != "watch" && action != "cancel" && action != "delete" &&
      action != "result")
    return report_error("jobs", "unknown action '" + action + "' (list, show, watch, cancel, delete, result)",
                        EXIT_BAD_INPUT);
  if (needs_id && parsed->positionals.size() != 1) return report_error(command, "expected one job ID", EXIT_BAD_INPUT);
  if (!needs_id && !parsed->positionals.empty())
    return report_error(command, "unexpected argument '" + parsed->positionals.front() + "'", EXIT_BAD_INPUT);
  const std::string job_id = needs_id ? parsed->positionals.front() : "";

  ConnectionOptions options = connection_options(*parsed);
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
      std::cout << to_json(reply) << std::endl;
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
      std::cout << to_json(job) << std::endl;
    else
      print_job(job);
    return EXIT_OK;
  }

  if (action == "watch") {
    ProgressPrinter printer(!json);
    const WatchOutcome outcome = watch_job(service, job_id, [&](const v1::JobEvent& event) {
      if (!json) {
        printer(event);
        return;
      }
      v1::JobEvent light = event;  // positions would make lines megabytes long: counts only
      if (light.has_mesh()) {
        light.mutable_mesh()->clear_positions_mm();
        light.mutable_mesh()->clear_triangles();
      }
      std::cout << to_json(light) << std::endl;
    });
    if (outcome.interrupted) {
      std::string where = service.embedded() ? " (in " + service.database() + "; it runs again when a balloon command "
                                                 "that runs jobs starts)"
                                             : "";
      std::fprintf(stderr, "\nstopped watching; job %s continues%s. Resume with: balloon jobs watch %s\n",
                   job_id.c_str(), where.c_str(), job_id.c_str());
      return EXIT_INTERRUPTED;
    }
    if (!outcome.status.ok()) return report_error(command, outcome.status.error_message(), exit_code_for(outcome.status));
    if (outcome.state == v1::JOB_STATE_COMPLETED) return outcome.converged ? EXIT_OK : EXIT_NOT_CONVERGED;
    return EXIT_JOB_FAILED;
  }

  return write_result(service, job_id, *parsed);
}

}  // namespace balloon::cli
