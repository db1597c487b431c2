#include "server_flags.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "service/shard_name.hpp"
#include "http/origin_policy.hpp"
#include "net/network_address.hpp"

namespace balloon::server {
namespace {

const std::map<std::string, bool>& known_flags() {
  // name -> takes a value
  static const std::map<std::string, bool> flags = {
      {"listen", true},       {"db", true},           {"workers", true},     {"max-queue", true},
      {"token-file", true},   {"tls-cert", true},     {"tls-key", true},     {"insecure-listen-any", false},
      {"max-message-mb", true}, {"max-mesh-vertices", true}, {"job-time-limit", true},
      {"progress-mesh-every", true}, {"quiet", false}, {"config", true}, {"help", false},
      {"http", true},         {"web-root", true},
      {"shard-name", true},   {"drain-timeout", true},
      {"http", true},         {"web-root", true},       {"http-allowed-origin", true},
      {"http-tls-cert", true}, {"http-tls-key", true},   {"http-max-event-streams", true},
      {"insecure-plaintext-tokens", false},
      // Job lifecycle and tenant quotas (README, "Service guarantees").
      {"max-attempts", true}, {"max-queued-per-tenant", true}, {"max-running-per-tenant", true},
      {"max-watches-per-tenant", true}, {"max-stored-mb-per-tenant", true}, {"retention-days", true},
  };
  return flags;
}

Result<long long> to_integer(const std::string& flag, const std::string& text, long long min_value, long long max_value) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) return fail("--" + flag + ": '" + text + "' is not an integer");
  if (value < min_value || value > max_value)
    return fail("--" + flag + ": " + text + " is outside " + std::to_string(min_value) + ".." + std::to_string(max_value));
  return value;
}

Result<double> to_number(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(value) || value <= 0.0)
    return fail("--" + flag + ": '" + text + "' is not a positive number");
  return value;
}

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

Result<bool> read_config_file(const std::string& path, std::vector<std::pair<std::string, std::string>>& settings) {
  std::ifstream in(path);
  if (!in) return fail("cannot read config file '" + path + "'");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    const auto eq = line.find('=');
    const std::string name = trim(line.substr(0, eq));
    const std::string value = eq == std::string::npos ? "" : trim(line.substr(eq + 1));
    const auto flag = known_flags().find(name);
    if (flag == known_flags().end() || name == "config" || name == "help")
      return fail("config file '" + path + "' line " + std::to_string(number) + ": unknown setting '" + name + "'");
    if (flag->second && eq == std::string::npos)
      return fail("config file '" + path + "' line " + std::to_string(number) + ": '" + name + "' needs '= value'");
    // Booleans: "name" or "name = true|false".
    if (!flag->second && (value == "false" || value == "0")) continue;
    settings.emplace_back(name, value);
  }
  return true;
}

}  // namespace

std::string default_web_root() {
#ifdef BALLOON_WEB_ROOT_FROM_BIN
  const std::filesystem::path from_bin = BALLOON_WEB_ROOT_FROM_BIN;
#else
  const std::filesystem::path from_bin = "../share/balloon/web";
#endif
  std::error_code error;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error || executable.empty()) return from_bin.string();  // no /proc: relative to the working directory
  return (executable.parent_path() / from_bin).lexically_normal().string();
}

std::string server_usage() {
  return "Usage: balloon-server [--listen ADDR] [--db PATH] [--workers N] [--max-queue N] [--token-file F]\n"
         "                      [--tls-cert F --tls-key F] [options]\n\n"
         "Runs the balloon design service (gRPC, package balloon.v1) with a job queue, worker threads and a\n"
         "SQLite store. Stops cleanly on SIGTERM or SIGINT: running jobs go back to the queue in the store\n"
         "and run again at the next start.\n\n"
         "Options (default in brackets):\n"
         "  --listen ADDR            address to listen on, host:port or unix:PATH [127.0.0.1:50051]; port 0 picks one\n"
         "  --db PATH                SQLite database file [balloon.db]\n"
         "  --workers N              worker threads running jobs [number of cores]\n"
         "  --max-queue N            queued jobs at most; more get RESOURCE_EXHAUSTED [1000]\n"
         "  --max-message-mb N       largest request or response in MiB [64]\n"
         "  --max-mesh-vertices N    largest mesh accepted, in vertices [200000]\n"
         "  --job-time-limit S       wall-time limit per job in seconds [3600]\n"
         "  --progress-mesh-every K  stream the intermediate mesh every K shape updates [1]\n"
         "  --token-file F           require 'authorization: Bearer <token>'; lines 'TENANT TOKEN' or\n"
         "                           'TENANT TOKEN raise-priority' (may submit priority above 0) [none]\n"
         "  --tls-cert F, --tls-key F  serve TLS with this PEM certificate chain and key [plaintext]\n"
         "  --http HOST:PORT         also serve the JSON API (/api/v1) and the web page over HTTP on this\n"
         "                           address, e.g. 127.0.0.1:8080; port 0 picks one [off]\n"
         "  --web-root DIR           the web page's files [" + default_web_root() + "]\n"
         "  --shard-name NAME        prefix every new job id with NAME ('s2' gives s2-j-...); calls on another\n"
         "                           shard's job answer FAILED_PRECONDITION; a-z, 0-9, '-', <= 32 chars [none]\n"
         "  --drain-timeout S        on SIGTERM: NOT_SERVING at once, new jobs refused (UNAVAILABLE), running\n"
         "                           jobs re-queued; the process ends within S seconds [30]\n"
         "  --http-tls-cert F, --http-tls-key F  serve the HTTP side as HTTPS with this PEM certificate chain\n"
         "                           and key [plaintext]\n"
         "  --http-allowed-origin URL  also accept requests from the page at URL (SCHEME://HOST[:PORT], e.g.\n"
         "                           https://balloon.example) and with its host in the Host header; repeatable.\n"
         "                           Otherwise only loopback names with the HTTP port are served [none]\n"
         "  --http-max-event-streams N  open job event streams at most; more get 503 [64]\n"
         "  --insecure-listen-any    allow non-loopback --listen/--http addresses without a token file [off]\n"
         "  --insecure-plaintext-tokens  allow tokens over plaintext gRPC/HTTP on non-loopback addresses\n"
         "                           (e.g. behind a proxy that terminates TLS) [off]\n"
         "  --max-attempts N         a job found running at start after N starts (it crashed the server N\n"
         "                           times) FAILS instead of running again; 0 no limit [3]\n"
         "  --max-queued-per-tenant N   queued jobs per tenant; more get RESOURCE_EXHAUSTED; 0 no limit [100]\n"
         "  --max-running-per-tenant N  jobs of one tenant running at once; 0 no limit [4]\n"
         "  --max-watches-per-tenant N  open watch streams per tenant; 0 no limit [64]\n"
         "  --max-stored-mb-per-tenant N  MiB of jobs and results a tenant may store; 0 no limit [2048]\n"
         "  --retention-days D       delete finished jobs older than D days, at start and hourly; 0 keeps\n"
         "                           them forever [90]\n"
         "  --quiet                  no per-job log lines on stderr [off]\n"
         "  --config FILE            read 'name = value' settings first (names as the flags) [none]\n"
         "  --help                   this text\n\n"
         "Health checking (grpc.health.v1) and server reflection are enabled. The HTTP API calls the same\n"
         "service in-process: same tokens ('Authorization: Bearer <token>'), limits and messages.\n";
}

Result<ServerCommand> parse_server_flags(const std::vector<std::string>& args) {
  std::vector<std::pair<std::string, std::string>> settings;
  std::vector<std::pair<std::string, std::string>> from_command_line;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (word.rfind("--", 0) != 0) return fail("unexpected argument '" + word + "'");
    std::string name = word.substr(2), value;
    bool inline_value = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      inline_value = true;
    }
    const auto flag = known_flags().find(name);
    if (flag == known_flags().end()) return fail("unknown option '--" + name + "'");
    if (flag->second && !inline_value) {
      if (i + 1 >= args.size()) return fail("option '--" + name + "' needs a value");
      value = args[++i];
    }
    if (name == "config") {
      Result<bool> read = read_config_file(value, settings);
      if (!read) return fail(read.error());
      continue;
    }
    from_command_line.emplace_back(name, value);
  }
  settings.insert(settings.end(), from_command_line.begin(), from_command_line.end());

  ServerCommand command;
  rpc::ServerConfig& config = command.config;
  config.listen_address = "127.0.0.1:50051";
  for (const auto& [name, value] : settings) {
    if (name == "help") command.help = true;
    else if (name == "quiet") command.quiet = true;
    else if (name == "insecure-listen-any") config.insecure_listen_any = true;
    else if (name == "listen") config.listen_address = value;
    else if (name == "db") config.service.db_path = value;
    else if (name == "token-file") config.token_file = value;
    else if (name == "tls-cert") config.tls_cert_file = value;
    else if (name == "tls-key") config.tls_key_file = value;
    else if (name == "http") command.http_address = value;
    else if (name == "web-root") command.web_root = value;
    else if (name == "shard-name") {
      Result<std::string> shard = service::check_shard_name(value);
      if (!shard) return fail(shard.error());
      config.service.shard_name = *shard;
    } else if (name == "drain-timeout") {
      Result<double> s = to_number(name, value);
      if (!s || *s > 3600.0) return fail("--drain-timeout: '" + value + "' is not a number of seconds in (0, 3600]");
      command.drain_timeout_s = *s;
    }
    else if (name == "http-allowed-origin") command.http_allowed_origins.push_back(value);
    else if (name == "http-tls-cert") command.http_tls_cert_file = value;
    else if (name == "http-tls-key") command.http_tls_key_file = value;
    else if (name == "insecure-plaintext-tokens") config.insecure_plaintext_tokens = true;
    else if (name == "http-max-event-streams") {
      Result<long long> n = to_integer(name, value, 1, 1000);
      if (!n) return fail(n.error());
      command.http_max_event_streams = static_cast<int>(*n);
    }
    else if (name == "workers") {
      Result<long long> n = to_integer(name, value, 1, 1024);
      if (!n) return fail(n.error());
      config.service.workers = static_cast<int>(*n);
    } else if (name == "max-queue") {
      Result<long long> n = to_integer(name, value, 1, 10000000);
      if (!n) return fail(n.error());
      config.service.max_queue = static_cast<int>(*n);
    } else if (name == "max-message-mb") {
      Result<long long> n = to_integer(name, value, 1, 2047);
      if (!n) return fail(n.error());
      config.max_message_bytes = static_cast<int>(*n) << 20;
    } else if (name == "max-mesh-vertices") {
      Result<long long> n = to_integer(name, value, 4, 100000000);
      if (!n) return fail(n.error());
      config.service.max_mesh_vertices = static_cast<int>(*n);
    } else if (name == "job-time-limit") {
      Result<double> s = to_number(name, value);
      if (!s) return fail(s.error());
      config.service.job_time_limit_s = *s;
    } else if (name == "max-attempts" || name == "max-queued-per-tenant" || name == "max-running-per-tenant" ||
               name == "max-watches-per-tenant" || name == "max-stored-mb-per-tenant") {
      Result<long long> n = to_integer(name, value, 0, 10000000);
      if (!n) return fail(n.error());
      balloon::service::ServiceOptions& service = config.service;
      int& target = name == "max-attempts"             ? service.max_attempts
                    : name == "max-queued-per-tenant"  ? service.max_queued_per_tenant
                    : name == "max-running-per-tenant" ? service.max_running_per_tenant
                    : name == "max-watches-per-tenant" ? service.max_watches_per_tenant
                                                       : service.max_stored_mb_per_tenant;
      target = static_cast<int>(*n);
    } else if (name == "retention-days") {
      char* end = nullptr;
      const double days = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0' || !std::isfinite(days) || days < 0.0 || days > 1e6)
        return fail("--retention-days: '" + value + "' is not a number of days within 0..1000000");
      config.service.retention_days = days;
    } else if (name == "progress-mesh-every") {
      Result<long long> n = to_integer(name, value, -1, 1000000);
      if (!n) return fail(n.error());
      config.service.progress_mesh_every = static_cast<int>(*n);
    }
  }
  if (command.web_root.empty()) command.web_root = default_web_root();
  for (const std::string& origin : command.http_allowed_origins) {
    Result<http::WebOrigin> parsed = http::parse_origin(origin);
    if (!parsed) return fail("--http-allowed-origin: " + parsed.error());
  }
  if (command.http_tls_cert_file.empty() != command.http_tls_key_file.empty())
    return fail("HTTPS needs both --http-tls-cert and --http-tls-key");
  if (command.http_address.empty() && (!command.http_tls_cert_file.empty() || !command.http_allowed_origins.empty()))
    return fail("--http-tls-cert, --http-tls-key and --http-allowed-origin need --http HOST:PORT");
  // The same rules as for --listen (GrpcServer::start): a port anyone can reach needs tokens, and tokens
  // that cross the network need TLS.
  // An address that does not parse is left to HttpGateway::start, which names the problem.
  const bool http_off_loopback = !command.http_address.empty() &&
                                 net::split_host_port(command.http_address).ok() &&
                                 !net::is_loopback_address(command.http_address);
  if (http_off_loopback && config.token_file.empty() && !config.insecure_listen_any)
    return fail("refusing to serve HTTP on '" + command.http_address +
                "' without --token-file (anyone could submit jobs); use a loopback address, a token file, or "
                "--insecure-listen-any");
  if (http_off_loopback && !config.token_file.empty() && command.http_tls_cert_file.empty() &&
      !config.insecure_plaintext_tokens)
    return fail("refusing to accept tokens over plaintext HTTP on '" + command.http_address +
                "' (anyone on the network path could read them); give --http-tls-cert and --http-tls-key, use a "
                "loopback address, or --insecure-plaintext-tokens (e.g. behind a proxy that terminates TLS)");
  if (config.service.workers <= 0) config.service.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return command;
}

}  // namespace balloon::server
