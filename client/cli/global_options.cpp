#include "global_options.hpp"

#include <cstdlib>

#include "arg_parser.hpp"

namespace balloon::cli {

Result<SplitCommandLine> split_global_options(const std::vector<std::string>& args) {
  // Booleans may repeat (`balloon --json jobs list --json` means what it says); values may not.
  static const std::vector<OptionSpec> SPECS = {{"server"},           {"token"},           {"tls-ca"},
                                                {"db"},               {"tls", false, true}, {"json", false, true},
                                                {"help", false, true}};
  std::vector<std::string> words;
  words.reserve(args.size());
  for (const std::string& word : args) {
    if (word == "--") break;
    words.push_back(word == "-h" ? "--help" : word);
  }
  words.insert(words.end(), args.begin() + static_cast<std::ptrdiff_t>(words.size()), args.end());

  SplitCommandLine split;
  Result<ParsedArgs> taken = take_options(words, SPECS, &split.words);
  if (!taken) return fail(taken.error());
  for (const char* name : {"server", "token", "tls-ca", "db"})
    if (const auto value = taken->get(name); value && value->empty())
      return fail("option '--" + std::string(name) + "' needs a value");

  const auto given = [&](const char* name, const char* env) -> std::string {
    if (const auto value = taken->get(name)) return *value;
    const char* from_env = env != nullptr ? std::getenv(env) : nullptr;
    return from_env != nullptr ? from_env : "";
  };
  ConnectionOptions& connection = split.global.connection;
  connection.server = given("server", "BALLOON_SERVER");
  connection.token = given("token", "BALLOON_TOKEN");
  connection.db = given("db", nullptr);
  connection.tls_ca = given("tls-ca", nullptr);
  connection.tls = taken->has("tls") || !connection.tls_ca.empty();
  split.global.json = taken->has("json");
  split.global.help = taken->has("help");
  return split;
}

const char* global_options_help() {
  return "Global options (before or after the command):\n"
         "  --server HOST:PORT  a balloon-server (env BALLOON_SERVER); default: an embedded in-process server\n"
         "  --token TOKEN       bearer token for the server (env BALLOON_TOKEN)\n"
         "  --tls               use TLS with the system's root certificates\n"
         "  --tls-ca FILE       use TLS trusting the PEM certificate(s) in FILE\n"
         "  --db PATH           embedded server's database [$XDG_DATA_HOME/balloon/balloon.db]\n"
         "  --json              machine-readable output on stdout\n"
         "  --help, -h          help (of the command, when one is given)\n";
}

std::string command_prefix(const ConnectionOptions& connection) {
  std::string command = "balloon";
  if (!connection.server.empty()) {
    command += " --server " + connection.server;
    if (!connection.tls_ca.empty())
      command += " --tls-ca " + connection.tls_ca;
    else if (connection.tls)
      command += " --tls";
  } else if (!connection.db.empty()) {
    command += " --db " + connection.db;
  }
  return command;
}

std::string resume_command(const ConnectionOptions& connection, const std::string& job_id) {
  return command_prefix(connection) + " jobs watch " + job_id;
}

}  // namespace balloon::cli
