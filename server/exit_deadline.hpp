#pragma once
/// The bound on draining (`balloon-server --drain-timeout`): once SIGTERM arrived the process ends within
/// the timeout even if a job ignores its cancel token for longer or a call hangs. Ending hard is safe:
/// a job still marked running in the store is re-queued at the next start, as after a crash.
#include <functional>
#include <string>

namespace balloon::server {

/// Starts a detached thread that, `timeout_s` seconds from now, logs one line and ends the process with
/// exit status 1 (std::_Exit: no destructors, which may be what hangs).
void exit_after(double timeout_s, const std::function<void(const std::string&)>& log);

}  // namespace balloon::server
