#include "embedded/embedded_server.hpp"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "rpc/grpc_server.hpp"

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

EmbeddedServer::EmbeddedServer(std::unique_ptr<rpc::GrpcServer> server) : m_server(std::move(server)) {}

EmbeddedServer::~EmbeddedServer() = default;

Result<std::unique_ptr<EmbeddedServer>> EmbeddedServer::start(const EmbeddedOptions& options) {
  rpc::ServerConfig config;  // no listen address: in-process only
  config.service.db_path = options.db_path;
  config.service.run_jobs = options.run_jobs;
  config.service.workers = 0;  // number of cores
  // The embedded server serves one user on this machine: no limits beyond the defaults' sanity, no
  // tenant quotas, and the user's history is never deleted behind their back (no retention).
  config.service.max_queued_per_tenant = 0;
  config.service.max_running_per_tenant = 0;
  config.service.max_watches_per_tenant = 0;
  config.service.max_stored_mb_per_tenant = 0;
  config.service.retention_days = 0.0;
  std::error_code ignored;
  const std::filesystem::path parent = std::filesystem::path(config.service.db_path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
  auto server = rpc::GrpcServer::start(config);
  if (!server) return fail(server.error());
  return std::unique_ptr<EmbeddedServer>(new EmbeddedServer(std::move(*server)));
}

std::shared_ptr<grpc::Channel> EmbeddedServer::channel() { return m_server->in_process_channel(); }

void EmbeddedServer::shutdown(double grace_s) { m_server->shutdown(grace_s); }

}  // namespace balloon::embedded
