#pragma once
/// Runs a program as a child process and captures its exit code, stdout and stderr: how the CLI and
/// server tests exercise the binaries from outside, the way users and CI do.
#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace balloon::testing {

struct ProcessResult {
  int exit_code = -1;   ///< exit status, or 128 + signal number if killed by a signal
  std::string out;      ///< everything written to stdout
  std::string err;      ///< everything written to stderr
};

/// Runs `program` with `args`, extra environment variables `env` (added to ours; an empty value
/// unsets), and `stdin_text` on its stdin; waits for it to finish.
ProcessResult run_process(const std::string& program, const std::vector<std::string>& args,
                          const std::map<std::string, std::string>& env = {}, const std::string& stdin_text = "");

/// A child process that runs while the test acts on it (a signal at the right moment), with its output
/// collected. Killed at destruction if still running.
class RunningProcess {
 public:
  /// Starts `program` with `args` and `env` (as run_process; stdin closed).
  RunningProcess(const std::string& program, const std::vector<std::string>& args,
                 const std::map<std::string, std::string>& env = {});
  ~RunningProcess();
  RunningProcess(const RunningProcess&) = delete;
  RunningProcess& operator=(const RunningProcess&) = delete;

  /// Collects output until its stderr contains `needle` (true) or `timeout_s` passed or it ended (false).
  bool wait_for_stderr(const std::string& needle, double timeout_s);
  /// Sends `signal_number` to the process.
  void send_signal(int signal_number);
  /// Collects the rest of its output and waits for its exit.
  ProcessResult wait();
  /// What it wrote so far.
  const ProcessResult& so_far() const { return m_result; }

 private:
  pid_t m_pid = -1;
  int m_fds[2] = {-1, -1};  ///< its stdout and stderr
  ProcessResult m_result;
};

/// Lines of `text`, without their newlines; a trailing newline adds no empty line.
std::vector<std::string> split_lines(const std::string& text);

}  // namespace balloon::testing
