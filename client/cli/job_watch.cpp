#include "job_watch.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include "cli_output.hpp"
#include "exit_codes.hpp"
#include "global_options.hpp"

namespace balloon::cli {
namespace {

std::atomic<int> g_interrupts{0};
extern "C" void on_interrupt(int) { g_interrupts.fetch_add(1); }

}  // namespace

InterruptCatcher::InterruptCatcher() {
  g_interrupts.store(0);
  m_previous = std::signal(SIGINT, on_interrupt);
}

InterruptCatcher::~InterruptCatcher() { std::signal(SIGINT, m_previous); }

int InterruptCatcher::count() const { return g_interrupts.load(); }

bool InterruptCatcher::wait_for(int presses, double seconds) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (count() < presses) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

void cancel_job(ServiceConnection& connection, const std::string& job_id) {
  grpc::ClientContext context;
  connection.prepare(context);
  balloon::v1::CancelJobRequest request;
  request.set_job_id(job_id);
  balloon::v1::Job job;
  connection.stub().CancelJob(&context, request, &job);
}

std::string state_name(balloon::v1::JobState state) {
  switch (state) {
    case balloon::v1::JOB_STATE_QUEUED: return "queued";
    case balloon::v1::JOB_STATE_RUNNING: return "running";
    case balloon::v1::JOB_STATE_COMPLETED: return "completed";
    case balloon::v1::JOB_STATE_FAILED: return "failed";
    case balloon::v1::JOB_STATE_CANCELLED: return "cancelled";
    default: return "unknown";
  }
}

bool is_final(balloon::v1::JobState state) {
  return state == balloon::v1::JOB_STATE_COMPLETED || state == balloon::v1::JOB_STATE_FAILED ||
         state == balloon::v1::JOB_STATE_CANCELLED;
}

WatchOutcome watch_job(ServiceConnection& connection, const std::string& job_id, const InterruptCatcher& interrupts,
                       const std::function<void(const balloon::v1::JobEvent&)>& on_event) {
  WatchOutcome outcome;
  grpc::ClientContext context;
  connection.prepare(context);
  balloon::v1::WatchJobRequest request;
  request.set_job_id(job_id);

  // A blocking Read cannot see a signal: this thread turns Ctrl-C into a cancelled call. It looks every
  // 20 ms, but waits on `stream_ended` so the end of the stream releases it at once (a plain sleep kept
  // every command waiting up to 20 ms more at its end).
  std::mutex mutex;
  std::condition_variable stream_ended;
  bool done = false;
  std::thread monitor([&] {
    std::unique_lock<std::mutex> lock(mutex);
    while (!stream_ended.wait_for(lock, std::chrono::milliseconds(20), [&] { return done; })) {
      if (interrupts.count() > 0) {
        connection.try_cancel(context);
        return;
      }
    }
  });
  auto reader = connection.stub().WatchJob(&context, request);
  balloon::v1::JobEvent event;
  while (reader->Read(&event)) {
    outcome.state = event.state();
    if (!event.message().empty()) outcome.message = event.message();
    if (event.state() == balloon::v1::JOB_STATE_COMPLETED) outcome.converged = event.converged();
    on_event(event);
  }
  outcome.status = reader->Finish();
  {
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
  }
  stream_ended.notify_one();
  monitor.join();
  outcome.interrupted = interrupts.count() > 0;
  return outcome;
}

ProgressPrinter::ProgressPrinter(bool enabled) : m_enabled(enabled), m_terminal(isatty(STDERR_FILENO) == 1) {}

ProgressPrinter::~ProgressPrinter() {
  if (m_line_open) std::fputc('\n', stderr);
}

void ProgressPrinter::operator()(const balloon::v1::JobEvent& event) {
  if (!m_enabled) return;
  char line[256];
  // The phases after a design that carry no pressure or residual of their own, by what they do.
  static const std::map<std::string, std::string> quiet_phases = {
      {"check", "inflating the designed rest shape from rest, as balloon simulate does"},
      {"tolerance", "inflating copies of the design with thickness errors"}};
  const auto quiet = event.has_progress() ? quiet_phases.find(event.progress().phase()) : quiet_phases.end();
  if (quiet != quiet_phases.end()) {
    std::snprintf(line, sizeof(line), "%s [%6.2f s] %s", event.job_id().c_str(), event.progress().elapsed_s(),
                  quiet->second.c_str());
  } else if (event.has_progress()) {
    const auto& p = event.progress();
    int n = std::snprintf(line, sizeof(line), "%s [%6.2f s] %s %d  p=%.4g kPa  residual %.2e N", event.job_id().c_str(),
                          p.elapsed_s(), p.phase().c_str(), p.iteration(), p.pressure_kpa(), p.residual_norm());
    if (p.avg_error_mm() >= 0 && n > 0 && n < static_cast<int>(sizeof(line)))
      std::snprintf(line + n, sizeof(line) - static_cast<std::size_t>(n), "  error avg %.3g max %.3g mm",
                    p.avg_error_mm(), p.max_error_mm());
  } else {
    // State messages read as sentences already ("started (attempt 1)", "completed: converged in 0.2 s").
    std::snprintf(line, sizeof(line), "%s %s", event.job_id().c_str(),
                  event.message().empty() ? state_name(event.state()).c_str() : event.message().c_str());
  }
  if (m_terminal && event.has_progress()) {
    std::fprintf(stderr, "\r\033[K%s", line);
    m_line_open = true;
  } else {
    if (m_line_open) std::fputc('\n', stderr);
    m_line_open = false;
    std::fprintf(stderr, "%s\n", line);
  }
  std::fflush(stderr);
}

int handle_interrupt(ServiceConnection& connection, const std::string& command, const std::string& job_id,
                     const InterruptPolicy& policy, const InterruptCatcher& interrupts) {
  const std::string prefix = "balloon " + command + ": ";
  if (policy.cancel) {
    cancel_job(connection, job_id);
    std::fprintf(stderr, "\n%sinterrupted; job %s cancelled\n", prefix.c_str(), job_id.c_str());
    return EXIT_INTERRUPTED;
  }
  // Detach: the job is the user's work, often minutes of it; a second Ctrl-C is the way to stop it.
  const int presses = interrupts.count();
  if (connection.embedded()) {
    // The embedded server stops with this process: its shutdown puts the running job back in the queue
    // of the local store, and the next command that runs jobs (jobs watch) recovers and runs it.
    std::fprintf(stderr,
                 "\n%sinterrupted; job %s stays queued in %s; resuming runs it again\n"
                 "resume with: %s\n(Ctrl-C again within 1 s cancels it)\n",
                 prefix.c_str(), job_id.c_str(), connection.database().c_str(),
                 resume_command(policy.connection, job_id).c_str());
  } else {
    std::fprintf(stderr,
                 "\n%sinterrupted; job %s keeps running on %s\n"
                 "resume with: %s\n(Ctrl-C again within 1 s cancels it)\n",
                 prefix.c_str(), job_id.c_str(), policy.connection.server.c_str(),
                 resume_command(policy.connection, job_id).c_str());
  }
  std::fflush(stderr);
  if (interrupts.count() > presses || interrupts.wait_for(presses + 1, 1.0)) {
    cancel_job(connection, job_id);
    std::fprintf(stderr, "%sjob %s cancelled\n", prefix.c_str(), job_id.c_str());
  }
  return EXIT_INTERRUPTED;
}

int follow_to_completion(ServiceConnection& connection, const std::string& command, const std::string& job_id,
                         const InterruptPolicy& policy,
                         const std::function<void(const balloon::v1::JobEvent&)>& on_event) {
  const InterruptCatcher interrupts;
  const WatchOutcome outcome = watch_job(connection, job_id, interrupts, on_event);
  if (outcome.interrupted) return handle_interrupt(connection, command, job_id, policy, interrupts);
  if (!outcome.status.ok()) return report_error(command, outcome.status.error_message(), exit_code_for(outcome.status));
  if (outcome.state != balloon::v1::JOB_STATE_COMPLETED)
    return report_error(command, "job " + job_id + " " + state_name(outcome.state) + ": " + outcome.message,
                        EXIT_JOB_FAILED);
  return EXIT_OK;
}

}  // namespace balloon::cli
