#include "subprocess.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace balloon::testing {
namespace {

/// Starts `program` with its stdin, stdout and stderr on pipes; returns the pid and our ends.
pid_t spawn(const std::string& program, const std::vector<std::string>& args,
            const std::map<std::string, std::string>& env, int* in_fd, int* out_fd, int* err_fd) {
  int out_pipe[2], err_pipe[2], in_pipe[2];
  if (pipe(out_pipe) != 0 || pipe(err_pipe) != 0 || pipe(in_pipe) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    dup2(in_pipe[0], STDIN_FILENO);
    dup2(out_pipe[1], STDOUT_FILENO);
    dup2(err_pipe[1], STDERR_FILENO);
    for (int fd : {in_pipe[0], in_pipe[1], out_pipe[0], out_pipe[1], err_pipe[0], err_pipe[1]}) close(fd);
    for (const auto& [name, value] : env) {
      if (value.empty())
        unsetenv(name.c_str());
      else
        setenv(name.c_str(), value.c_str(), 1);
    }
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(program.c_str()));
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    execv(program.c_str(), argv.data());
    _exit(127);
  }
  close(in_pipe[0]);
  close(out_pipe[1]);
  close(err_pipe[1]);
  *in_fd = in_pipe[1];
  *out_fd = out_pipe[0];
  *err_fd = err_pipe[0];
  return pid;
}

/// Reads what is ready on `fds` (stdout, stderr) within `timeout_ms` (-1: until something is) into the
/// result; closes and marks -1 the pipes that ended. False once both ended.
bool pump(int fds[2], ProcessResult& result, int timeout_ms) {
  pollfd polled[2] = {{fds[0], POLLIN, 0}, {fds[1], POLLIN, 0}};
  if (fds[0] < 0 && fds[1] < 0) return false;
  if (poll(polled, 2, timeout_ms) < 0) return true;
  std::string* sinks[2] = {&result.out, &result.err};
  char buffer[65536];
  for (int i = 0; i < 2; ++i) {
    if (fds[i] < 0 || polled[i].revents == 0) continue;
    const ssize_t n = read(fds[i], buffer, sizeof(buffer));
    if (n > 0) {
      sinks[i]->append(buffer, static_cast<std::size_t>(n));
    } else {
      close(fds[i]);
      fds[i] = -1;
    }
  }
  return fds[0] >= 0 || fds[1] >= 0;
}

int exit_code_of(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

ProcessResult run_process(const std::string& program, const std::vector<std::string>& args,
                          const std::map<std::string, std::string>& env, const std::string& stdin_text) {
  int in_fd = -1, fds[2] = {-1, -1};
  const pid_t pid = spawn(program, args, env, &in_fd, &fds[0], &fds[1]);
  // Feed stdin (small texts only) and close it so the child sees EOF.
  if (!stdin_text.empty()) {
    signal(SIGPIPE, SIG_IGN);
    [[maybe_unused]] const ssize_t written = write(in_fd, stdin_text.data(), stdin_text.size());
  }
  close(in_fd);
  ProcessResult result;
  while (pump(fds, result, -1)) {
  }
  result.exit_code = exit_code_of(pid);
  return result;
}

RunningProcess::RunningProcess(const std::string& program, const std::vector<std::string>& args,
                               const std::map<std::string, std::string>& env) {
  int in_fd = -1;
  m_pid = spawn(program, args, env, &in_fd, &m_fds[0], &m_fds[1]);
  close(in_fd);
}

RunningProcess::~RunningProcess() {
  if (m_pid <= 0) return;
  kill(m_pid, SIGKILL);
  wait();
}

bool RunningProcess::wait_for_stderr(const std::string& needle, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (m_result.err.find(needle) == std::string::npos) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    if (!pump(m_fds, m_result, 50)) return m_result.err.find(needle) != std::string::npos;
  }
  return true;
}

void RunningProcess::send_signal(int signal_number) {
  if (m_pid > 0) kill(m_pid, signal_number);
}

ProcessResult RunningProcess::wait() {
  while (pump(m_fds, m_result, -1)) {
  }
  if (m_pid > 0) m_result.exit_code = exit_code_of(m_pid);
  m_pid = -1;
  return m_result;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

}  // namespace balloon::testing
