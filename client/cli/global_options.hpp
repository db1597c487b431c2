#pragma once
/// The flags every `balloon` command shares (--server, --token, --tls, --tls-ca, --db, --json, --help),
/// accepted before or after the subcommand as in git, kubectl and gh: one parser, used by every command.
#include <string>
#include <vector>

#include "result.hpp"
#include "service_connection.hpp"

namespace balloon::cli {

struct GlobalOptions {
  ConnectionOptions connection;  ///< --server/BALLOON_SERVER, --token/BALLOON_TOKEN, --tls, --tls-ca, --db
  bool json = false;             ///< --json: machine-readable output on stdout
  bool help = false;             ///< --help or -h
};

/// A command line with the global flags taken out.
struct SplitCommandLine {
  GlobalOptions global;
  std::vector<std::string> words;  ///< everything else, in order: the subcommand and its own arguments
};

/// Takes the global flags out of `args` (the words after `balloon`), wherever they stand, up to a `--`
/// (kept in `words` with everything after it). Errors name the flag: a missing value, or a value flag
/// given twice.
Result<SplitCommandLine> split_global_options(const std::vector<std::string>& args);

/// The help text of the global flags, for `balloon --help` and each command's --help.
const char* global_options_help();

/// "balloon" with the flags that reach the same service: --server (and --tls or --tls-ca), or --db.
std::string command_prefix(const ConnectionOptions& connection);

/// The command that re-attaches to `job_id` with the same connection flags, e.g.
/// "balloon --server HOST:PORT jobs watch ID" (never the token: it is a secret, and the environment or
/// the same --token supplies it).
std::string resume_command(const ConnectionOptions& connection, const std::string& job_id);

}  // namespace balloon::cli
