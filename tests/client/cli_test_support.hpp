#pragma once
/// Shared pieces of the CLI tests: the binary under test, a scratch directory, flat-JSON field lookup.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "subprocess.hpp"

namespace balloon::testing {

/// A fresh directory under the system temp dir, removed with everything in it at destruction.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return m_path; }
  std::string file(const std::string& name) const { return (m_path / name).string(); }

 private:
  std::filesystem::path m_path;
};

/// Runs the `balloon` binary with its data directory inside `scratch`, so tests never touch ~/.local.
ProcessResult run_balloon(const ScratchDir& scratch, const std::vector<std::string>& args,
                          const std::map<std::string, std::string>& env = {});

/// Starts the `balloon` binary as run_balloon does, without waiting for it.
std::unique_ptr<RunningProcess> start_balloon(const ScratchDir& scratch, const std::vector<std::string>& args,
                                              const std::map<std::string, std::string>& env = {});

/// The raw text of a top-level member of a one-line JSON object: `"key":VALUE` -> VALUE
/// (strings keep their quotes). Enough for our flat reports; nullopt if the key is absent.
std::optional<std::string> json_field(const std::string& json, const std::string& key);
/// json_field parsed as a number; NaN if absent or not a number.
double json_number_field(const std::string& json, const std::string& key);

}  // namespace balloon::testing
