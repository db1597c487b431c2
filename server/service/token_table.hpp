#pragma once
/// Bearer tokens and the tenants they stand for, loaded from a token file. Lookups compare against
/// every token in constant time (for a given presented length), and tokens are never printed.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "result.hpp"

namespace balloon::service {

class TokenTable {
 public:
  /// Reads a token file: one token per line, `TENANT TOKEN` or just `TOKEN` (the tenant is then
  /// "tenant-<line number>"); blank lines and lines starting with '#' are skipped. Tokens must be at
  /// least 16 characters. Errors name the line, never the token.
  static Result<TokenTable> load(const std::string& path);
  /// A table from (tenant, token) pairs (tests).
  static TokenTable from_pairs(std::vector<std::pair<std::string, std::string>> pairs);

  /// The tenant whose token equals `presented`, checking every token without early exit.
  std::optional<std::string> tenant_for(std::string_view presented) const;
  std::size_t size() const { return m_entries.size(); }

 private:
  struct Entry {
    std::string tenant;
    std::string token;
  };
  std::vector<Entry> m_entries;
};

/// True if a == b, in time that depends only on a.size() (the caller's own input), not on b.
bool constant_time_equals(std::string_view a, std::string_view b);

}  // namespace balloon::service
