#pragma once
/// Which requests the HTTP gateway serves, judged by their `Host` and `Origin` headers (README.md,
/// "Security"). A browser attaches `Origin` to every cross-origin request that can change something, so a
/// page on another site cannot drive the API (CSRF); a checked `Host` stops DNS rebinding, where another
/// site's name is pointed at 127.0.0.1 so that the browser treats this server as that site.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "result.hpp"

namespace balloon::http {

/// A web origin as browsers send it: scheme ("http" or "https"), host in lower case (IPv6 without
/// brackets) and port (the scheme's default when the text has none).
struct WebOrigin {
  std::string scheme;
  std::string host;
  int port = 0;
  bool operator==(const WebOrigin& other) const {
    return scheme == other.scheme && host == other.host && port == other.port;
  }
};

/// Parses "SCHEME://HOST[:PORT]" (an `Origin` header or an --http-allowed-origin value; one trailing "/"
/// is accepted). Fails naming the problem: other schemes, a path, user info, a bad port.
Result<WebOrigin> parse_origin(std::string_view text);

/// Parses a `Host` header, "HOST[:PORT]" or "[V6][:PORT]", into lower-case host (no brackets) and port
/// (`default_port` when absent).
Result<std::pair<std::string, int>> parse_host_header(std::string_view text, int default_port);

class OriginPolicy {
 public:
  /// The gateway serves `https` when `tls`, on `port`; `allowed` are the --http-allowed-origin values.
  OriginPolicy(bool tls, int port, std::vector<WebOrigin> allowed);

  /// Empty when a request with these headers (nullptr: header absent) may be served, else the reason to
  /// refuse it (a 403's message). The Host must be a loopback name with the gateway's port, or the host
  /// of an allowed origin. An Origin, when present, must be this gateway's loopback origin (same scheme
  /// and port) or one of the allowed origins; a request without one (curl, scripts) is judged by Host alone.
  std::string refusal(const std::string* host, const std::string* origin) const;

 private:
  std::string m_scheme;
  int m_port = 0;
  std::vector<WebOrigin> m_allowed;
};

}  // namespace balloon::http
