#include "server_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace balloon::testing {

ServerProcess::ServerProcess(const std::string& db_path, const std::vector<std::string>& extra_args) {
  m_log_path = db_path + ".server.log";
  int out_pipe[2];
  if (pipe(out_pipe) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> args = {BALLOON_SERVER_PATH, "--listen", "127.0.0.1:0", "--db", db_path, "--quiet"};
  args.insert(args.end(), extra_args.begin(), extra_args.end());
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
  std::string output;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (output.find('\n') == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    pollfd fd{out_pipe[0], POLLIN, 0};
    if (poll(&fd, 1, 200) <= 0) continue;
    char buffer[512];
    const ssize_t n = read(out_pipe[0], buffer, sizeof(buffer));
    if (n <= 0) break;
    output.append(buffer, static_cast<std::size_t>(n));
  }
  close(out_pipe[0]);
  const std::string marker = "listening on 127.0.0.1:";
  const auto at = output.find(marker);
  if (at == std::string::npos) {
    stop(SIGKILL);
    throw std::runtime_error("balloon-server did not start: " + output + log());
  }
  m_port = std::stoi(output.substr(at + marker.size()));
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

}  // namespace balloon::testing
