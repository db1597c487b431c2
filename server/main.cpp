/// balloon-server: the design service on a port. See server_usage() for the flags.
#include <pthread.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <mutex>

#include "http/http_gateway.hpp"
#include "rpc/grpc_server.hpp"
#include "server_flags.hpp"

namespace {

std::mutex g_log_mutex;

/// One timestamped line on stderr per job event. Never given tokens.
void log_line(const std::string& line) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const int millis = static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%S", &utc);
  std::lock_guard lock(g_log_mutex);
  std::fprintf(stderr, "%s.%03dZ %s\n", stamp, millis, line.c_str());
  std::fflush(stderr);
}

}  // namespace

int main(int argc, char** argv) {
  balloon::Result<balloon::server::ServerCommand> command =
      balloon::server::parse_server_flags(std::vector<std::string>(argv + 1, argv + argc));
  if (!command) {
    std::fprintf(stderr, "balloon-server: error: %s (see --help)\n", command.error().c_str());
    return 2;
  }
  if (command->help) {
    std::fputs(balloon::server::server_usage().c_str(), stdout);
    return 0;
  }
  // Block SIGTERM and SIGINT in every thread (threads inherit the mask); the main thread waits for them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  // A browser that goes away mid-response must cost a failed write, not the process (httplib sends
  // without MSG_NOSIGNAL).
  signal(SIGPIPE, SIG_IGN);

  balloon::rpc::ServerConfig config = command->config;
  if (!command->quiet) config.service.log = log_line;
  auto server = balloon::rpc::GrpcServer::start(config);
  if (!server) {
    std::fprintf(stderr, "balloon-server: error: %s\n", server.error().c_str());
    return 1;
  }
  // Tests and scripts read this line to learn the port (with --listen HOST:0).
  std::string where = config.listen_address;
  if (where.rfind("unix:", 0) != 0) {
    where.resize(where.rfind(':') + 1);
    where.append(std::to_string((*server)->port()));
  }
  std::unique_ptr<balloon::http::HttpGateway> gateway;
  if (!command->http_address.empty()) {
    balloon::http::HttpGatewayOptions options;
    options.address = command->http_address;
    options.web_root = command->web_root;
    options.max_body_bytes = static_cast<std::size_t>(config.max_message_bytes);
    options.allowed_origins = command->http_allowed_origins;
    options.tls_cert_file = command->http_tls_cert_file;
    options.tls_key_file = command->http_tls_key_file;
    options.max_event_streams = command->http_max_event_streams;
    options.log = log_line;
    auto started = balloon::http::HttpGateway::start(options, (*server)->in_process_channel());
    if (!started) {
      std::fprintf(stderr, "balloon-server: error: %s\n", started.error().c_str());
      (*server)->shutdown(1.0);
      return 1;
    }
    gateway = std::move(*started);
  }
  std::printf("balloon-server listening on %s (db %s, %d workers, %s%s)\n", where.c_str(),
              config.service.db_path.c_str(), config.service.workers,
              config.token_file.empty() ? "no authentication" : "token authentication",
              config.tls_cert_file.empty() ? "" : ", TLS");
  if (gateway) {
    std::string http_where = command->http_address;
    http_where.resize(http_where.rfind(':') + 1);
    http_where.append(std::to_string(gateway->port()));
    std::printf("balloon-server http on %s (%sweb root %s)\n", http_where.c_str(),
                command->http_tls_cert_file.empty() ? "" : "https, ", command->web_root.c_str());
  }
  // One flush for both lines: readers that stop after the first line still find the pipe's whole write.
  std::fflush(stdout);

  int received = 0;
  sigwait(&signals, &received);
  log_line(std::string("received ") + (received == SIGTERM ? "SIGTERM" : "SIGINT") + "; shutting down");
  // The gateway first: it ends its event streams and stops taking requests while the service still answers.
  if (gateway) gateway->stop();
  (*server)->shutdown(5.0);
  server->reset();  // closes the store
  log_line("stopped");
  return 0;
}
