#pragma once
/// The in-process service the CLI uses when no --server is given: the same store, queue, workers and
/// handlers as balloon-server, on a local SQLite file, reached through the generated stub interface
/// implemented in-process (rpc/direct_stub: no gRPC server, no port, no serialization). The CLI sees only
/// this class and the stub interface, never the service's internals.
#include <memory>
#include <string>

#include <grpcpp/client_context.h>

#include "balloon/v1/balloon.grpc.pb.h"
#include "result.hpp"

namespace balloon::embedded {

struct EmbeddedOptions {
  std::string db_path;   ///< SQLite file (its folder is created); ":memory:" for a throw-away store
  bool run_jobs = true;  ///< false: store and queue jobs but start no workers (commands that do not wait)
  /// false: jobs an earlier process left unfinished stay queued and are not run here, so a command's own
  /// job does not wait behind them (a command killed mid-job leaves its job running in the store)
  bool run_recovered = true;
};

/// One user's service on this machine: no tenant quotas and no retention (their history is never deleted
/// behind their back), workers on every core, commits not flushed to disk (a crash of the process loses
/// nothing; a crash of the machine may lose the last jobs).
class EmbeddedServer {
 public:
  /// Opens the store, recovers its unfinished jobs and starts the workers. Errors name the problem.
  static Result<std::unique_ptr<EmbeddedServer>> start(const EmbeddedOptions& options);
  ~EmbeddedServer();

  /// The service's API, called in this process (synchronous calls only).
  balloon::v1::BalloonService::StubInterface& stub();
  /// Ends a WatchJob stream opened with `context` (ClientContext::TryCancel does not reach it).
  void cancel(grpc::ClientContext* context);
  /// Stops the workers (running jobs stay queued in the store), waiting at most `grace_s`. Idempotent.
  void shutdown(double grace_s);

 private:
  struct Internals;
  explicit EmbeddedServer(std::unique_ptr<Internals> internals);
  std::unique_ptr<Internals> m_internals;
};

/// The embedded server's default database: $XDG_DATA_HOME/balloon/balloon.db, else
/// ~/.local/share/balloon/balloon.db.
std::string default_database_path();

}  // namespace balloon::embedded
