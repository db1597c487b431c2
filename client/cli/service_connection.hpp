#pragma once
/// How the CLI reaches the service: a remote server (--server / BALLOON_SERVER, with --token /
/// BALLOON_TOKEN) or, by default, an embedded in-process server on a local SQLite file (same service
/// code, called in-process through the same stub interface: no port, no gRPC server).
#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "balloon/v1/balloon.grpc.pb.h"
#include "result.hpp"

namespace balloon::embedded {
class EmbeddedServer;
}

namespace balloon::cli {

struct ConnectionOptions {
  std::string server;    ///< HOST:PORT; empty: embedded server
  std::string token;     ///< bearer token for a remote server
  std::string db;        ///< embedded server's database; empty: $XDG_DATA_HOME/balloon/balloon.db
  std::string tls_ca;    ///< PEM root certificate(s) for TLS to a remote server
  bool tls = false;      ///< TLS with the system roots
  bool run_jobs = true;  ///< embedded server: start workers (commands that wait for jobs)
  bool run_recovered = true;  ///< embedded server: also run the jobs earlier processes left unfinished
};

class ServiceConnection {
 public:
  /// Connects (remote) or starts the embedded server. Errors name the problem.
  static Result<std::unique_ptr<ServiceConnection>> open(const ConnectionOptions& options);
  ~ServiceConnection();

  balloon::v1::BalloonService::StubInterface& stub() { return *m_stub; }
  /// Cancels the call (or WatchJob stream) made with `context`, remote or in-process.
  void try_cancel(grpc::ClientContext& context);
  /// Adds the token to a call's metadata.
  void prepare(grpc::ClientContext& context) const;
  /// SubmitJob with the token: returns once the job is stored and queued. Gives `request` a request id
  /// if it has none (in place: an uploaded mesh is not copied).
  grpc::Status submit(balloon::v1::SubmitJobRequest& request, balloon::v1::SubmitJobResponse* reply);
  /// True for the embedded server.
  bool embedded() const { return m_embedded != nullptr; }
  /// Where the embedded server keeps its data (empty for a remote server).
  const std::string& database() const { return m_database; }

 private:
  ServiceConnection() = default;
  std::unique_ptr<embedded::EmbeddedServer> m_embedded;
  std::shared_ptr<grpc::Channel> m_channel;                              // remote only
  std::unique_ptr<balloon::v1::BalloonService::StubInterface> m_remote_stub;  // remote only
  balloon::v1::BalloonService::StubInterface* m_stub = nullptr;
  std::string m_token;
  std::string m_database;
};

/// The CLI exit code for a failed call (exit_codes.hpp).
int exit_code_for(const grpc::Status& status);

}  // namespace balloon::cli
