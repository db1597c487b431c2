#pragma once
/// Following a job from the CLI: stream its events until it finishes, show progress on stderr, and turn
/// Ctrl-C into a detach (the job keeps running; the resume command is printed) or, on request, a cancel.
#include <functional>
#include <string>

#include "balloon/v1/balloon.pb.h"
#include "service_connection.hpp"

namespace balloon::cli {

/// Catches Ctrl-C (SIGINT) while alive and counts the presses; restores the previous handler at the end.
class InterruptCatcher {
 public:
  InterruptCatcher();
  ~InterruptCatcher();
  InterruptCatcher(const InterruptCatcher&) = delete;
  InterruptCatcher& operator=(const InterruptCatcher&) = delete;
  /// Presses since construction.
  int count() const;
  /// Waits up to `seconds` for the count to reach `presses`; true if it did.
  bool wait_for(int presses, double seconds) const;

 private:
  void (*m_previous)(int);
};

struct WatchOutcome {
  grpc::Status status;                                           ///< of the stream (OK when the job finished)
  balloon::v1::JobState state = balloon::v1::JOB_STATE_UNSPECIFIED;  ///< last state seen
  bool converged = false;                                        ///< from the COMPLETED event
  std::string message;                                           ///< last state message (the error when FAILED)
  bool interrupted = false;                                      ///< stopped by Ctrl-C
};

/// Streams `job_id`'s events to `on_event` until the job reaches a final state, the stream fails, or
/// Ctrl-C is (or was, since `interrupts` started catching) pressed.
WatchOutcome watch_job(ServiceConnection& connection, const std::string& job_id, const InterruptCatcher& interrupts,
                       const std::function<void(const balloon::v1::JobEvent&)>& on_event);

/// Asks the service to cancel `job_id` (best effort: after Ctrl-C the CLI exits either way).
void cancel_job(ServiceConnection& connection, const std::string& job_id);

/// What Ctrl-C does to a followed job.
struct InterruptPolicy {
  bool cancel = false;           ///< --cancel-on-interrupt: cancel the job (else detach; a second Ctrl-C cancels)
  ConnectionOptions connection;  ///< how this process connected, for the resume command
};

/// After Ctrl-C stopped following `job_id`: cancels it (policy.cancel, or a second Ctrl-C within a
/// second), or says on stderr where it continues and the command that resumes watching it. Returns
/// EXIT_INTERRUPTED.
int handle_interrupt(ServiceConnection& connection, const std::string& command, const std::string& job_id,
                     const InterruptPolicy& policy, const InterruptCatcher& interrupts);

/// Follows a submitted job to its end for `command`, with its events to `on_event`; Ctrl-C as `policy`
/// says. EXIT_OK once it completed; otherwise says why on stderr and returns the exit code (interrupted,
/// the stream's error, or EXIT_JOB_FAILED when the job failed or was cancelled).
int follow_to_completion(ServiceConnection& connection, const std::string& command, const std::string& job_id,
                         const InterruptPolicy& policy,
                         const std::function<void(const balloon::v1::JobEvent&)>& on_event);

/// Prints progress events on stderr: one updating line on a terminal, plain lines otherwise.
class ProgressPrinter {
 public:
  /// `enabled` false prints nothing.
  explicit ProgressPrinter(bool enabled);
  ~ProgressPrinter();
  void operator()(const balloon::v1::JobEvent& event);

 private:
  bool m_enabled;
  bool m_terminal;
  bool m_line_open = false;
};

/// "queued", "running", ... for a state.
std::string state_name(balloon::v1::JobState state);
/// A final state: completed, failed or cancelled.
bool is_final(balloon::v1::JobState state);

}  // namespace balloon::cli
