#pragma once
/// Runs a program as a child process and captures its exit code, stdout and stderr: how the CLI and
/// server tests exercise the binaries from outside, the way users and CI do.
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

/// Lines of `text`, without their newlines; a trailing newline adds no empty line.
std::vector<std::string> split_lines(const std::string& text);

}  // namespace balloon::testing
