#pragma once
/// Following a job from the CLI: stream its events until it finishes, show progress on stderr, and let
/// Ctrl-C stop the watching (the caller decides whether that also cancels the job).
#include <functional>
#include <string>

#include "balloon/v1/balloon.pb.h"
#include "service_connection.hpp"

namespace balloon::cli {

struct WatchOutcome {
  grpc::Status status;                                           ///< of the stream (OK when the job finished)
  balloon::v1::JobState state = balloon::v1::JOB_STATE_UNSPECIFIED;  ///< last state seen
  bool converged = false;                                        ///< from the COMPLETED event
  std::string message;                                           ///< last state message (the error when FAILED)
  bool interrupted = false;                                      ///< stopped by Ctrl-C
};

/// Streams `job_id`'s events to `on_event` until the job reaches a final state, the stream fails, or
/// Ctrl-C is pressed.
WatchOutcome watch_job(ServiceConnection& connection, const std::string& job_id,
                       const std::function<void(const balloon::v1::JobEvent&)>& on_event);

/// Asks the service to cancel `job_id` (best effort: after Ctrl-C the CLI exits either way).
void cancel_job(ServiceConnection& connection, const std::string& job_id);

/// Follows a submitted job to its end for `command`, with its events to `on_event`, cancelling it on
/// Ctrl-C. EXIT_OK once it completed; otherwise says why on stderr and returns the exit code
/// (interrupted, the stream's error, or EXIT_JOB_FAILED when the job failed or was cancelled).
int follow_to_completion(ServiceConnection& connection, const std::string& command, const std::string& job_id,
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
