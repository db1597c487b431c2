#pragma once
/// balloon-server's command line (and optional key = value config file) into a ServerConfig.
#include <string>
#include <vector>

#include "result.hpp"
#include "rpc/grpc_server.hpp"

namespace balloon::server {

/// What the command line asked for.
struct ServerCommand {
  rpc::ServerConfig config;
  std::string http_address;  ///< --http HOST:PORT: also serve the JSON API and the page; empty: no HTTP
  std::string web_root;      ///< --web-root DIR: the page's files (default: default_web_root())
  std::vector<std::string> http_allowed_origins;  ///< --http-allowed-origin URL (repeatable), checked
  std::string http_tls_cert_file;  ///< --http-tls-cert FILE: serve HTTPS with this PEM certificate chain
  std::string http_tls_key_file;   ///< --http-tls-key FILE: and this PEM key
  int http_max_event_streams = 64;  ///< --http-max-event-streams N: more get 503
  bool help = false;   ///< print server_usage() and exit
  bool quiet = false;  ///< no per-job log lines
  double drain_timeout_s = 30.0;  ///< --drain-timeout S: after SIGTERM the process ends within this (s)
};

/// Parses the words after the program name. `--config FILE` reads `name = value` lines (names as the
/// flags without dashes; `#` comments) before the remaining flags, which override it.
Result<ServerCommand> parse_server_flags(const std::vector<std::string>& args);

/// The --web-root default: share/balloon/web of the install prefix, found from the executable's folder
/// (BALLOON_WEB_ROOT_FROM_BIN, e.g. "../share/balloon/web", so a moved prefix still finds its page). The build
/// tree mirrors that layout with a link to the page CMake builds (server/CMakeLists.txt).
std::string default_web_root();

/// The --help text, with every flag's default.
std::string server_usage();

}  // namespace balloon::server
