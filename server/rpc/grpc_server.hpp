#pragma once
/// A running balloon service: the store, the handlers, the workers and the gRPC server around them.
/// balloon-server listens on a port; the CLI embeds one with no port and talks to it in-process.
#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "result.hpp"
#include "service/service_options.hpp"

namespace balloon::rpc {

struct ServerConfig {
  service::ServiceOptions service;      ///< store, workers, limits, log
  std::string listen_address;           ///< "127.0.0.1:50051"; empty: in-process only (embedded)
  std::string token_file;               ///< empty: no authentication (then loopback only)
  std::string tls_cert_file;            ///< PEM certificate chain; with tls_key_file enables TLS
  std::string tls_key_file;             ///< PEM private key
  bool insecure_listen_any = false;     ///< allow a non-loopback address without a token file
  bool insecure_plaintext_tokens = false;  ///< allow tokens on a non-loopback address without TLS
  int max_message_bytes = 64 << 20;     ///< largest request or response (bytes)
};

class GrpcServer {
 public:
  /// Opens the store, recovers unfinished jobs, starts workers and the server. Errors name the problem
  /// (bad flags, unreadable token file or certificate, store that cannot be opened, port in use). A
  /// non-loopback address needs a token file (or insecure_listen_any), and tokens off loopback need TLS
  /// (or insecure_plaintext_tokens).
  static Result<std::unique_ptr<GrpcServer>> start(const ServerConfig& config);
  ~GrpcServer();

  /// The port bound (useful with port 0); 0 when in-process only.
  int port() const;
  /// A channel to this server that bypasses the network (same service code, no port).
  std::shared_ptr<grpc::Channel> in_process_channel();
  /// Jobs re-queued from the store at start.
  int recovered_jobs() const;
  /// Jobs running on the workers now (the benches' "every worker busy").
  int running_jobs() const;

  /// Tells health checks (grpc.health.v1, service "") NOT_SERVING from now on: the first step of a drain.
  void report_not_serving();
  /// Stops accepting jobs, stops running ones (re-queued in the store), ends watch streams, then shuts
  /// the gRPC server down, waiting at most `grace_s` for calls in flight. Idempotent.
  void shutdown(double grace_s = 5.0);
  /// Blocks until shutdown() has completed.
  void wait();

 private:
  struct Internals;
  explicit GrpcServer(std::unique_ptr<Internals> internals);
  std::unique_ptr<Internals> m_internals;
};

}  // namespace balloon::rpc
