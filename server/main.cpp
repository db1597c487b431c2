/// balloon-server: the design service on a port. See server_usage() for the flags.
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <mutex>

#include "exit_deadline.hpp"
#include "http/http_gateway.hpp"
#include "rpc/grpc_server.hpp"
#include "server_flags.hpp"

namespace {

std::mutex g_log_mutex;

// SIGTERM/SIGINT arrive through a handler, not sigwait: threads that libraries start before main (OpenBLAS's)
// do not block them, and the default action there would kill the process instead of draining it.
sem_t g_stop_requested;
volatile sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int signal_number) {
  g_stop_signal = signal_number;
  sem_post(&g_stop_requested);  // async-signal-safe
}

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
  // Block SIGTERM and SIGINT in the threads the server starts (they inherit the mask); the main thread takes them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  sem_init(&g_stop_requested, 0, 0);
  struct sigaction on_stop {};
  on_stop.sa_handler = on_stop_signal;
  on_stop.sa_flags = SA_RESTART;
  sigemptyset(&on_stop.sa_mask);
  sigaction(SIGTERM, &on_stop, nullptr);
  sigaction(SIGINT, &on_stop, nullptr);
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

  pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);  // the server's threads keep them blocked; this one takes them
  while (sem_wait(&g_stop_requested) != 0) {
  }
  const int received = g_stop_signal;
  char drain_seconds[32];
  std::snprintf(drain_seconds, sizeof(drain_seconds), "%g", command->drain_timeout_s);
  log_line(std::string("received ") + (received == SIGTERM ? "SIGTERM" : "SIGINT") +
           "; draining: NOT_SERVING, new jobs refused, running jobs re-queued, exit within " + drain_seconds + " s");
  (*server)->report_not_serving();
  balloon::server::exit_after(command->drain_timeout_s, log_line);
  // The gateway first: it ends its event streams and stops taking requests while the service still answers.
  if (gateway) gateway->stop();
  // Unary calls in flight finish within milliseconds; streams that never end by themselves (a balancer's
  // grpc.health.v1 Watch) are cut after this grace, well inside the drain timeout.
  (*server)->shutdown(std::min(5.0, command->drain_timeout_s * 0.5));
  server->reset();  // closes the store
  log_line("stopped");
  return 0;
}
