#pragma once
/// The in-process service the CLI uses when no --server is given: the same store, queue, workers and gRPC
/// service as balloon-server, on a local SQLite file, reached through a channel with no port. The CLI
/// sees only this class and the generated stub, never the service's internals.
#include <memory>
#include <string>

#include <grpcpp/channel.h>

#include "result.hpp"

namespace balloon::rpc {
class GrpcServer;
}

namespace balloon::embedded {

struct EmbeddedOptions {
  std::string db_path;   ///< SQLite file (its folder is created); ":memory:" for a throw-away store
  bool run_jobs = true;  ///< false: store and queue jobs but start no workers (commands that do not wait)
};

/// One user's service on this machine: no tenant quotas and no retention (their history is never deleted
/// behind their back), workers on every core.
class EmbeddedServer {
 public:
  /// Opens the store, recovers its unfinished jobs and starts the workers. Errors name the problem.
  static Result<std::unique_ptr<EmbeddedServer>> start(const EmbeddedOptions& options);
  ~EmbeddedServer();

  /// A channel to the service that bypasses the network.
  std::shared_ptr<grpc::Channel> channel();
  /// Stops the workers (running jobs stay queued in the store), waiting at most `grace_s`. Idempotent.
  void shutdown(double grace_s);

 private:
  explicit EmbeddedServer(std::unique_ptr<rpc::GrpcServer> server);
  std::unique_ptr<rpc::GrpcServer> m_server;
};

/// The embedded server's default database: $XDG_DATA_HOME/balloon/balloon.db, else
/// ~/.local/share/balloon/balloon.db.
std::string default_database_path();

}  // namespace balloon::embedded
