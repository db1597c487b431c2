#pragma once
/// Bearer tokens and the tenants they stand for, loaded from a token file. Lookups compare against
/// every token in constant time (for a given presented length), and tokens are never printed.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "result.hpp"
#include "service/caller.hpp"

namespace balloon::service {

class TokenTable {
 public:
  /// Reads a token file: one token per line, `TENANT TOKEN [raise-priority]` or just `TOKEN` (the tenant
  /// is then "tenant-<line number>"); blank lines and lines starting with '#' are skipped. Tokens must be
  /// at least 16 characters; a token or a tenant that appears twice is refused (two tenants sharing a
  /// token would see each other's jobs). `raise-priority` lets the tenant submit jobs with priority above
  /// 0. Errors name the line, never the token.
  static Result<TokenTable> load(const std::string& path);
  /// A table from (tenant, token) pairs (tests); no tenant may raise priority.
  static TokenTable from_pairs(std::vector<std::pair<std::string, std::string>> pairs);

  /// The caller whose token equals `presented`, checking every token without early exit.
  std::optional<Caller> caller_for(std::string_view presented) const;
  std::size_t size() const { return m_entries.size(); }

 private:
  struct Entry {
    std::string tenant;
    std::string token;
    bool may_raise_priority = false;
  };
  std::vector<Entry> m_entries;
};

/// True if a == b, in time that depends only on a.size() (the caller's own input), not on b.
bool constant_time_equals(std::string_view a, std::string_view b);

}  // namespace balloon::service
