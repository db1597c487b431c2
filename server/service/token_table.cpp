#include "service/token_table.hpp"

#include <fstream>
#include <map>
#include <set>

namespace balloon::service {
namespace {

/// The token file's third word: the tenant may submit jobs with priority above 0.
constexpr const char* RAISE_PRIORITY = "raise-priority";

}  // namespace

bool constant_time_equals(std::string_view a, std::string_view b) {
  // Walk a's length whatever b is; index into b modulo its size so no early exit leaks b's length
  // or content through timing.
  unsigned difference = static_cast<unsigned>(a.size() ^ b.size());
  if (b.empty()) return a.empty();
  for (std::size_t i = 0; i < a.size(); ++i)
    difference |= static_cast<unsigned char>(a[i]) ^ static_cast<unsigned char>(b[i % b.size()]);
  // volatile keeps the compiler from turning the loop into an early-exit comparison.
  volatile unsigned result = difference;
  return result == 0;
}

Result<TokenTable> TokenTable::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return fail("cannot read token file '" + path + "'");
  TokenTable table;
  std::set<std::string> tenants;
  std::map<std::string, int> token_lines;  // token -> the line it first appeared on
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> words;
    std::size_t start = first;
    while (start != std::string::npos && start < line.size()) {
      const auto end = line.find_first_of(" \t", start);
      words.push_back(line.substr(start, end == std::string::npos ? std::string::npos : end - start));
      start = end == std::string::npos ? end : line.find_first_not_of(" \t", end);
    }
    const std::string where = "token file '" + path + "' line " + std::to_string(number) + ": ";
    Entry entry;
    if (words.size() == 1) {
      entry.tenant = "tenant-" + std::to_string(number);
      entry.token = words[0];
    } else if (words.size() == 2 || words.size() == 3) {
      entry.tenant = words[0];
      entry.token = words[1];
      if (words.size() == 3) {
        if (words[2] != RAISE_PRIORITY)
          // Not quoted: a mistyped line may hold a second token there.
          return fail(where + "only '" + std::string(RAISE_PRIORITY) + "' may follow the token");
        entry.may_raise_priority = true;
      }
    } else {
      return fail(where + "expected 'TENANT TOKEN', 'TENANT TOKEN " + std::string(RAISE_PRIORITY) + "' or 'TOKEN'");
    }
    if (entry.token.size() < 16) return fail(where + "token shorter than 16 characters");
    if (!tenants.insert(entry.tenant).second) return fail(where + "tenant '" + entry.tenant + "' appears twice");
    if (const auto [earlier, inserted] = token_lines.emplace(entry.token, number); !inserted)
      return fail(where + "the same token as line " + std::to_string(earlier->second) +
                  " (each tenant needs its own token, or the two would share their jobs)");
    table.m_entries.push_back(std::move(entry));
  }
  if (table.m_entries.empty()) return fail("token file '" + path + "' holds no tokens");
  return table;
}

TokenTable TokenTable::from_pairs(std::vector<std::pair<std::string, std::string>> pairs) {
  TokenTable table;
  for (auto& [tenant, token] : pairs) table.m_entries.push_back({std::move(tenant), std::move(token)});
  return table;
}

std::optional<Caller> TokenTable::caller_for(std::string_view presented) const {
  const Entry* match = nullptr;
  for (const Entry& entry : m_entries)
    if (constant_time_equals(presented, entry.token) && match == nullptr) match = &entry;
  if (match == nullptr) return std::nullopt;
  Caller caller;
  caller.tenant = match->tenant;
  caller.may_raise_priority = match->may_raise_priority;
  return caller;
}

}  // namespace balloon::service
