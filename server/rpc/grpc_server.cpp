#include "rpc/grpc_server.hpp"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>

#include <fstream>
#include <mutex>
#include <sstream>

#include "net/network_address.hpp"
#include "rpc/balloon_service_impl.hpp"
#include "service/job_handler.hpp"
#include "service/material_handler.hpp"
#include "service/token_table.hpp"
#include "store/store.hpp"

namespace balloon::rpc {
namespace {

Result<std::string> read_file(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail("cannot read " + what + " '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

struct GrpcServer::Internals {
  std::unique_ptr<store::Store> store;
  std::unique_ptr<service::MaterialHandler> materials;
  std::unique_ptr<service::JobHandler> jobs;
  std::optional<service::TokenTable> tokens;
  std::unique_ptr<BalloonServiceImpl> service;
  std::unique_ptr<grpc::Server> server;
  int port = 0;
  int recovered = 0;
  std::mutex shutdown_mutex;
  bool shut_down = false;
};

GrpcServer::GrpcServer(std::unique_ptr<Internals> internals) : m_internals(std::move(internals)) {}

GrpcServer::~GrpcServer() { shutdown(); }

Result<std::unique_ptr<GrpcServer>> GrpcServer::start(const ServerConfig& config) {
  auto internals = std::make_unique<Internals>();
  const bool off_loopback = !config.listen_address.empty() && !net::is_loopback_address(config.listen_address);
  if (off_loopback && config.token_file.empty() && !config.insecure_listen_any)
    return fail("refusing to listen on '" + config.listen_address +
                "' without --token-file (anyone could submit jobs); use a loopback address, a token file, or "
                "--insecure-listen-any");
  if (config.tls_cert_file.empty() != config.tls_key_file.empty())
    return fail("TLS needs both --tls-cert and --tls-key");
  if (off_loopback && !config.token_file.empty() && config.tls_cert_file.empty() && !config.insecure_plaintext_tokens)
    return fail("refusing to accept tokens over plaintext gRPC on '" + config.listen_address +
                "' (anyone on the network path could read them); give --tls-cert and --tls-key, use a loopback "
                "address, or --insecure-plaintext-tokens (e.g. behind a proxy that terminates TLS)");
  if (!config.token_file.empty()) {
    Result<service::TokenTable> tokens = service::TokenTable::load(config.token_file);
    if (!tokens) return fail(tokens.error());
    internals->tokens = std::move(*tokens);
  }
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials();
  if (!config.tls_cert_file.empty()) {
    Result<std::string> cert = read_file(config.tls_cert_file, "TLS certificate");
    if (!cert) return fail(cert.error());
    Result<std::string> key = read_file(config.tls_key_file, "TLS key");
    if (!key) return fail(key.error());
    grpc::SslServerCredentialsOptions options;
    options.pem_key_cert_pairs.push_back({*key, *cert});
    credentials = grpc::SslServerCredentials(options);
  }

  try {
    internals->store = std::make_unique<store::Store>(config.service.db_path, store::StoreOptions{config.service.durable_store});
  } catch (const std::exception& error) {
    return fail(error.what());
  }
  internals->materials = std::make_unique<service::MaterialHandler>(*internals->store);
  internals->jobs = std::make_unique<service::JobHandler>(config.service, *internals->store, *internals->materials);
  internals->service = std::make_unique<BalloonServiceImpl>(
      *internals->jobs, *internals->materials, internals->tokens ? &*internals->tokens : nullptr, config.service.log,
      config.service.shard_name);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.SetMaxReceiveMessageSize(config.max_message_bytes);
  builder.SetMaxSendMessageSize(config.max_message_bytes);
  if (!config.listen_address.empty()) builder.AddListeningPort(config.listen_address, credentials, &internals->port);
  builder.RegisterService(internals->service.get());
  internals->server = builder.BuildAndStart();
  if (!internals->server) return fail("cannot start the gRPC server");
  if (!config.listen_address.empty() && internals->port == 0)
    return fail("cannot listen on '" + config.listen_address + "' (address in use or invalid)");
  if (auto* health = internals->server->GetHealthCheckService()) health->SetServingStatus(true);

  // Workers start last: a job must not run before the server could report on it.
  internals->recovered = internals->jobs->start();
  return std::unique_ptr<GrpcServer>(new GrpcServer(std::move(internals)));
}

int GrpcServer::port() const { return m_internals->port; }
int GrpcServer::recovered_jobs() const { return m_internals->recovered; }

int GrpcServer::running_jobs() const { return m_internals->jobs->running_count(); }

std::shared_ptr<grpc::Channel> GrpcServer::in_process_channel() {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(-1);
  arguments.SetMaxSendMessageSize(-1);
  return m_internals->server->InProcessChannel(arguments);
}

void GrpcServer::report_not_serving() {
  if (auto* health = m_internals->server->GetHealthCheckService()) health->SetServingStatus(false);
}

void GrpcServer::shutdown(double grace_s) {
  std::lock_guard lock(m_internals->shutdown_mutex);
  if (m_internals->shut_down) return;
  m_internals->shut_down = true;
  if (auto* health = m_internals->server->GetHealthCheckService()) health->SetServingStatus(false);
  // Jobs first: that ends the watch streams, which would otherwise hold the gRPC shutdown to its deadline.
  m_internals->jobs->shutdown();
  const auto deadline = std::chrono::system_clock::now() + std::chrono::milliseconds(static_cast<int>(grace_s * 1000));
  m_internals->server->Shutdown(deadline);
  m_internals->server->Wait();
}

void GrpcServer::wait() { m_internals->server->Wait(); }

}  // namespace balloon::rpc
