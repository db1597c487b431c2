#include "embedded/embedded_server.hpp"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "rpc/direct_stub.hpp"
#include "service/job_handler.hpp"
#include "service/material_handler.hpp"
#include "store/store.hpp"

namespace balloon::embedded {

std::string default_database_path() {
  std::filesystem::path base;
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg != '\0') {
    base = xdg;
  } else if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    base = std::filesystem::path(home) / ".local" / "share";
  } else {
    base = std::filesystem::temp_directory_path();
  }
  return (base / "balloon" / "balloon.db").string();
}

struct EmbeddedServer::Internals {
  std::unique_ptr<store::Store> store;
  std::unique_ptr<service::MaterialHandler> materials;
  std::unique_ptr<service::JobHandler> jobs;
  std::unique_ptr<rpc::DirectStub> stub;
  bool shut_down = false;
};

EmbeddedServer::EmbeddedServer(std::unique_ptr<Internals> internals) : m_internals(std::move(internals)) {}

EmbeddedServer::~EmbeddedServer() { shutdown(0.0); }

Result<std::unique_ptr<EmbeddedServer>> EmbeddedServer::start(const EmbeddedOptions& options) {
  service::ServiceOptions config;
  config.db_path = options.db_path;
  config.run_jobs = options.run_jobs;
  config.run_recovered = options.run_recovered;
  config.workers = 0;  // number of cores
  // The embedded server serves one user on this machine: no limits beyond the defaults' sanity, no
  // tenant quotas, and the user's history is never deleted behind their back (no retention).
  config.max_queued_per_tenant = 0;
  config.max_running_per_tenant = 0;
  config.max_watches_per_tenant = 0;
  config.max_stored_mb_per_tenant = 0;
  config.retention_days = 0.0;
  // A command's own history: no fsync on its path.
  config.durable_store = false;
  std::error_code ignored;
  const std::filesystem::path parent = std::filesystem::path(config.db_path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ignored);

  auto internals = std::make_unique<Internals>();
  try {
    internals->store = std::make_unique<store::Store>(config.db_path, store::StoreOptions{config.durable_store});
  } catch (const std::exception& error) {
    return fail(error.what());
  }
  internals->materials = std::make_unique<service::MaterialHandler>(*internals->store);
  internals->jobs = std::make_unique<service::JobHandler>(config, *internals->store, *internals->materials);
  service::Caller caller;  // the local tenant, as a server without a token file sees every caller
  caller.may_raise_priority = true;
  internals->stub = std::make_unique<rpc::DirectStub>(*internals->jobs, *internals->materials, caller);
  internals->jobs->start();
  return std::unique_ptr<EmbeddedServer>(new EmbeddedServer(std::move(internals)));
}

balloon::v1::BalloonService::StubInterface& EmbeddedServer::stub() { return *m_internals->stub; }

void EmbeddedServer::cancel(grpc::ClientContext* context) { m_internals->stub->cancel(context); }

void EmbeddedServer::shutdown(double) {
  // The workers stop at their next iteration (running jobs go back to the queue in the store); watch
  // streams end with UNAVAILABLE. Nothing else runs in-process, so there is no grace period to wait out.
  if (m_internals->shut_down) return;
  m_internals->shut_down = true;
  m_internals->jobs->shutdown();
}

}  // namespace balloon::embedded
