#pragma once
/// balloon-server's HTTP side: the JSON API under /api/v1 (README.md, "HTTP/JSON API") and the static web page.
/// Every API call goes to the gRPC service over a channel (the server's in-process one), carrying the
/// HTTP `Authorization` header as the metadata `authorization`: authentication, limits, checks and
/// messages are the service's own. Job progress is streamed as Server-Sent Events. Every request passes
/// the OriginPolicy (Host and Origin) first, and a body must be JSON (README.md, "Security").
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "result.hpp"

namespace grpc {
class Channel;
}

namespace balloon::http {

struct HttpGatewayOptions {
  std::string address;                 ///< "HOST:PORT" or "[V6]:PORT"; port 0 picks a free one
  std::string web_root;                ///< directory of the page (index.html ...); need not exist
  std::size_t max_body_bytes = 64u << 20;  ///< larger request bodies get 413 (the service's message limit)
  std::vector<std::string> allowed_origins;  ///< "SCHEME://HOST[:PORT]" pages besides loopback that may call
  std::string tls_cert_file;           ///< PEM certificate chain; with tls_key_file the gateway speaks HTTPS
  std::string tls_key_file;            ///< PEM private key
  /// Open event streams at most; more get 503. Each open stream holds a worker thread, so the pool has
  /// `threads` more than this: streams can never starve the other requests (/health included).
  int max_event_streams = 64;
  int threads = 16;                    ///< worker threads for everything but event streams
  /// One line per unexpected server-side problem (never tokens); empty for silence.
  std::function<void(const std::string&)> log;
};

class HttpGateway {
 public:
  /// Binds the address and starts serving, calling the service through `channel`. Fails with a message
  /// naming the problem (malformed address or allowed origin, unreadable certificate or key, port in use).
  static Result<std::unique_ptr<HttpGateway>> start(const HttpGatewayOptions& options,
                                                    std::shared_ptr<grpc::Channel> channel);
  /// Stops (see stop()).
  ~HttpGateway();
  HttpGateway(const HttpGateway&) = delete;
  HttpGateway& operator=(const HttpGateway&) = delete;

  /// The port bound (the chosen one with port 0).
  int port() const;
  /// Ends open event streams (`event: end` UNAVAILABLE), stops accepting connections and waits for the
  /// worker threads. Idempotent. Call before the gRPC server shuts down.
  void stop();

 private:
  struct Internals;
  explicit HttpGateway(std::unique_ptr<Internals> internals);
  std::unique_ptr<Internals> m_internals;
};

}  // namespace balloon::http
