#pragma once
/// A balloon-server child process on 127.0.0.1 with an ephemeral port, for service-level tests.
#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "balloon/v1/balloon.grpc.pb.h"

namespace balloon::testing {

class ServerProcess {
 public:
  /// Starts balloon-server with `--listen 127.0.0.1:0 --db db_path` (and `--quiet` when `quiet`) plus
  /// `extra_args` and waits (up to 20 s) for its "listening on" line, and with `--http` among the
  /// arguments for its "http on" line too. Throws std::runtime_error if it does not come up.
  ServerProcess(const std::string& db_path, const std::vector<std::string>& extra_args, bool quiet = true);
  /// SIGTERM and wait, if still running.
  ~ServerProcess();

  int port() const { return m_port; }
  /// The HTTP gateway's port (with `--http`), else 0.
  int http_port() const { return m_http_port; }
  /// What the server printed on stdout at start.
  const std::string& output() const { return m_output; }
  std::string address() const { return "127.0.0.1:" + std::to_string(m_port); }
  /// A stub on a fresh channel to this server.
  std::unique_ptr<balloon::v1::BalloonService::Stub> stub(int max_message_bytes = -1) const;

  /// Sends `signal` and waits for the exit; returns the exit code (128 + signal if killed).
  int stop(int signal);
  /// Whatever the server wrote on stderr so far (its log) — read after stop().
  std::string log() const;

 private:
  pid_t m_pid = -1;
  int m_port = 0;
  int m_http_port = 0;
  std::string m_output;
  std::string m_log_path;
};

/// Adds `authorization: Bearer token` to a context (no-op for an empty token).
void add_token(grpc::ClientContext& context, const std::string& token);

/// Every event of WatchJob until the stream ends (at most 90 s), and the stream's final status.
std::vector<balloon::v1::JobEvent> watch_all(balloon::v1::BalloonService::Stub& stub, const std::string& job_id,
                                             grpc::Status* status, const std::string& token = "");

}  // namespace balloon::testing
