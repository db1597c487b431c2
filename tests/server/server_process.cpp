#include "server_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace balloon::testing {

namespace {

/// True once `output` holds the whole line that starts at `marker`.
bool has_line(const std::string& output, const std::string& marker) {
  const auto at = output.find(marker);
  return at != std::string::npos && output.find('\n', at) != std::string::npos;
}

}  // namespace

ServerProcess::ServerProcess(const std::string& db_path, const std::vector<std::string>& extra_args, bool quiet) {
  m_log_path = db_path + ".server.log";
  int out_pipe[2];
  if (pipe(out_pipe) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> args = {BALLOON_SERVER_PATH, "--listen", "127.0.0.1:0", "--db", db_path};
  if (quiet) args.push_back("--quiet");
  args.insert(args.end(), extra_args.begin(), extra_args.end());
  const bool with_http = std::find(args.begin(), args.end(), "--http") != args.end();
  m_pid = fork();
  if (m_pid < 0) throw std::runtime_error("fork failed");
  if (m_pid == 0) {
    dup2(out_pipe[1], STDOUT_FILENO);
    const int log_fd = open(m_log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (log_fd >= 0) dup2(log_fd, STDERR_FILENO);
    close(out_pipe[0]);
    close(out_pipe[1]);
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(out_pipe[1]);
  const std::string grpc_marker = "listening on 127.0.0.1:", http_marker = "http on 127.0.0.1:";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((!has_line(m_output, grpc_marker) || (with_http && !has_line(m_output, http_marker))) &&
         std::chrono::steady_clock::now() < deadline) {
    pollfd fd{out_pipe[0], POLLIN, 0};
    if (poll(&fd, 1, 200) <= 0) continue;
    char buffer[512];
    const ssize_t n = read(out_pipe[0], buffer, sizeof(buffer));
    if (n <= 0) break;
    m_output.append(buffer, static_cast<std::size_t>(n));
  }
  close(out_pipe[0]);
  const auto grpc_at = m_output.find(grpc_marker), http_at = m_output.find(http_marker);
  if (grpc_at == std::string::npos || (with_http && http_at == std::string::npos)) {
    stop(SIGKILL);
    throw std::runtime_error("balloon-server did not start: " + m_output + log());
  }
  m_port = std::stoi(m_output.substr(grpc_at + grpc_marker.size()));
  if (with_http) m_http_port = std::stoi(m_output.substr(http_at + http_marker.size()));
}

ServerProcess::~ServerProcess() {
  if (m_pid > 0) stop(SIGTERM);
}

int ServerProcess::stop(int signal) {
  if (m_pid <= 0) return -1;
  kill(m_pid, signal);
  int status = 0;
  waitpid(m_pid, &status, 0);
  m_pid = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string ServerProcess::log() const {
  std::ifstream in(m_log_path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::unique_ptr<balloon::v1::BalloonService::Stub> ServerProcess::stub(int max_message_bytes) const {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(-1);
  arguments.SetMaxSendMessageSize(max_message_bytes);
  // A private channel per stub: tests that model separate clients get separate connections.
  arguments.SetInt("grpc.use_local_subchannel_pool", 1);
  return balloon::v1::BalloonService::NewStub(
      grpc::CreateCustomChannel(address(), grpc::InsecureChannelCredentials(), arguments));
}

void add_token(grpc::ClientContext& context, const std::string& token) {
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
}

std::vector<balloon::v1::JobEvent> watch_all(balloon::v1::BalloonService::Stub& stub, const std::string& job_id,
                                             grpc::Status* status, const std::string& token) {
  grpc::ClientContext context;
  add_token(context, token);
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(90));
  balloon::v1::WatchJobRequest request;
  request.set_job_id(job_id);
  auto reader = stub.WatchJob(&context, request);
  std::vector<balloon::v1::JobEvent> events;
  balloon::v1::JobEvent event;
  while (reader->Read(&event)) events.push_back(event);
  *status = reader->Finish();
  return events;
}

}  // namespace balloon::testing
