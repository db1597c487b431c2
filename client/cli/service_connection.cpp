#include "service_connection.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "exit_codes.hpp"
#include "embedded/embedded_server.hpp"

namespace balloon::cli {

ServiceConnection::~ServiceConnection() {
  m_stub = nullptr;
  m_remote_stub.reset();
  m_channel.reset();
  if (m_embedded) m_embedded->shutdown(2.0);
}

Result<std::unique_ptr<ServiceConnection>> ServiceConnection::open(const ConnectionOptions& options) {
  std::unique_ptr<ServiceConnection> connection(new ServiceConnection());
  if (!options.server.empty()) {
    std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
    if (options.tls) {
      grpc::SslCredentialsOptions ssl;
      if (!options.tls_ca.empty()) {
        std::ifstream in(options.tls_ca);
        if (!in) return fail("cannot read --tls-ca '" + options.tls_ca + "'");
        std::ostringstream pem;
        pem << in.rdbuf();
        ssl.pem_root_certs = pem.str();
      }
      credentials = grpc::SslCredentials(ssl);
    }
    grpc::ChannelArguments arguments;
    arguments.SetMaxReceiveMessageSize(-1);
    connection->m_channel = grpc::CreateCustomChannel(options.server, credentials, arguments);
    connection->m_token = options.token;
    connection->m_remote_stub = balloon::v1::BalloonService::NewStub(connection->m_channel);
    connection->m_stub = connection->m_remote_stub.get();
  } else {
    embedded::EmbeddedOptions embedded_options;
    embedded_options.db_path = options.db.empty() ? embedded::default_database_path() : options.db;
    embedded_options.run_jobs = options.run_jobs;
    embedded_options.run_recovered = options.run_recovered;
    auto server = embedded::EmbeddedServer::start(embedded_options);
    if (!server && options.db.empty()) {
      // No writable data directory (a read-only home, a bare container): keep working, without history.
      std::fprintf(stderr, "balloon: warning: %s; using a temporary in-memory job store\n", server.error().c_str());
      embedded_options.db_path = ":memory:";
      server = embedded::EmbeddedServer::start(embedded_options);
    }
    if (!server) return fail("cannot start the embedded server: " + server.error());
    connection->m_embedded = std::move(*server);
    connection->m_stub = &connection->m_embedded->stub();
    connection->m_database = embedded_options.db_path;
  }
  return connection;
}

void ServiceConnection::try_cancel(grpc::ClientContext& context) {
  context.TryCancel();
  if (m_embedded) m_embedded->cancel(&context);
}

void ServiceConnection::prepare(grpc::ClientContext& context) const {
  if (!m_token.empty()) context.AddMetadata("authorization", "Bearer " + m_token);
}

namespace {

/// Tries of one submission when the server cannot be reached (a lost reply included).
constexpr int SUBMIT_TRIES = 3;

/// 128 random bits as 32 hex digits: the submission's idempotency key.
std::string new_request_id() {
  std::random_device device;
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%08x%08x%08x%08x", device(), device(), device(), device());
  return buffer;
}

}  // namespace

grpc::Status ServiceConnection::submit(balloon::v1::SubmitJobRequest& sent, balloon::v1::SubmitJobResponse* reply) {
  // One request id per submission, reused by its retries: a reply lost on the way back must not leave
  // a second job behind (the server returns the first job for a repeated id).
  if (sent.request_id().empty()) sent.set_request_id(new_request_id());
  grpc::Status status;
  for (int attempt = 1; attempt <= SUBMIT_TRIES; ++attempt) {
    grpc::ClientContext context;
    prepare(context);
    status = m_stub->SubmitJob(&context, sent, reply);
    if (status.error_code() != grpc::StatusCode::UNAVAILABLE &&
        status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED)
      break;
    if (attempt < SUBMIT_TRIES) std::this_thread::sleep_for(std::chrono::milliseconds(250 * attempt));
  }
  return status;
}

int exit_code_for(const grpc::Status& status) {
  switch (status.error_code()) {
    case grpc::StatusCode::OK: return EXIT_OK;
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::UNIMPLEMENTED:
    case grpc::StatusCode::OUT_OF_RANGE: return EXIT_BAD_INPUT;
    case grpc::StatusCode::NOT_FOUND: return EXIT_NOT_FOUND;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
    case grpc::StatusCode::UNAVAILABLE:
    case grpc::StatusCode::DEADLINE_EXCEEDED: return EXIT_UNAVAILABLE;
    case grpc::StatusCode::UNAUTHENTICATED:
    case grpc::StatusCode::PERMISSION_DENIED: return EXIT_DENIED;
    case grpc::StatusCode::FAILED_PRECONDITION: return EXIT_NOT_READY;
    case grpc::StatusCode::CANCELLED: return EXIT_INTERRUPTED;
    default: return EXIT_INTERNAL;
  }
}

}  // namespace balloon::cli
