#include "cli_test_support.hpp"

#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace balloon::testing {

ScratchDir::ScratchDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "balloon-test-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  m_path = pattern;
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(m_path, ignored);
}

namespace {

/// The test's environment for the CLI: its data directory in `scratch`, no server or token from ours.
std::map<std::string, std::string> balloon_environment(const ScratchDir& scratch,
                                                       const std::map<std::string, std::string>& env) {
  std::map<std::string, std::string> full_env = {
      {"XDG_DATA_HOME", scratch.file("xdg-data")},
      {"BALLOON_SERVER", ""},
      {"BALLOON_TOKEN", ""},
  };
  for (const auto& [name, value] : env) full_env[name] = value;
  return full_env;
}

}  // namespace

ProcessResult run_balloon(const ScratchDir& scratch, const std::vector<std::string>& args,
                          const std::map<std::string, std::string>& env) {
  return run_process(BALLOON_CLI_PATH, args, balloon_environment(scratch, env));
}

std::unique_ptr<RunningProcess> start_balloon(const ScratchDir& scratch, const std::vector<std::string>& args,
                                              const std::map<std::string, std::string>& env) {
  return std::make_unique<RunningProcess>(BALLOON_CLI_PATH, args, balloon_environment(scratch, env));
}

std::optional<std::string> json_field(const std::string& json, const std::string& key) {
  // Walk the object tracking depth and strings, so keys of nested objects do not match.
  const std::string quoted = "\"" + key + "\"";
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '{' || c == '[') ++depth;
    else if (c == '}' || c == ']') --depth;
    else if (c == '"') {
      if (depth == 1 && json.compare(i, quoted.size(), quoted) == 0 && i + quoted.size() < json.size() &&
          json[i + quoted.size()] == ':') {
        std::size_t start = i + quoted.size() + 1, end = start;
        int value_depth = 0;
        bool value_string = false;
        for (; end < json.size(); ++end) {
          const char v = json[end];
          if (value_string) {
            if (v == '\\') ++end;
            else if (v == '"') value_string = false;
            continue;
          }
          if (v == '"') value_string = true;
          else if (v == '{' || v == '[') ++value_depth;
          else if (v == '}' || v == ']') {
            if (value_depth == 0) break;
            --value_depth;
          } else if (v == ',' && value_depth == 0) break;
        }
        return json.substr(start, end - start);
      }
      in_string = true;
    }
  }
  return std::nullopt;
}

double json_number_field(const std::string& json, const std::string& key) {
  const auto text = json_field(json, key);
  if (!text) return std::numeric_limits<double>::quiet_NaN();
  char* end = nullptr;
  const double value = std::strtod(text->c_str(), &end);
  if (end == text->c_str()) return std::numeric_limits<double>::quiet_NaN();
  return value;
}

}  // namespace balloon::testing
