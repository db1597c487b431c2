#include "service/shard_name.hpp"

namespace balloon::service {
namespace {

/// "j-" and 16 lowercase hex digits: the part of an id JobHandler::new_job_id generates.
constexpr std::size_t BASE_ID_LENGTH = 18;

bool is_base_id(const std::string& text, std::size_t from) {
  if (text.size() - from != BASE_ID_LENGTH || text.compare(from, 2, "j-") != 0) return false;
  for (std::size_t i = from + 2; i < text.size(); ++i) {
    const char c = text[i];
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

bool is_shard_character(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'; }

}  // namespace

Result<std::string> check_shard_name(const std::string& name) {
  if (name.empty()) return fail("--shard-name must not be empty");
  if (name.size() > MAX_SHARD_NAME_LENGTH)
    return fail("--shard-name is " + std::to_string(name.size()) + " characters; at most " +
                std::to_string(MAX_SHARD_NAME_LENGTH) + " allowed");
  for (const char c : name)
    if (!is_shard_character(c)) return fail("--shard-name '" + name + "' may use only a-z, 0-9 and '-'");
  return name;
}

std::string shard_job_id(const std::string& shard, const std::string& base_id) {
  return shard.empty() ? base_id : shard + "-" + base_id;
}

std::optional<std::string> shard_of_job_id(const std::string& job_id) {
  if (job_id.size() < BASE_ID_LENGTH) return std::nullopt;
  const std::size_t base = job_id.size() - BASE_ID_LENGTH;
  if (!is_base_id(job_id, base)) return std::nullopt;
  if (base == 0) return std::string();
  // "<shard>-j-...": a valid shard name, then the dash.
  if (base < 2 || job_id[base - 1] != '-') return std::nullopt;
  std::string shard = job_id.substr(0, base - 1);
  if (!check_shard_name(shard)) return std::nullopt;
  return shard;
}

ServiceStatus check_job_shard(const std::string& this_shard, const std::string& job_id) {
  const std::optional<std::string> owner = shard_of_job_id(job_id);
  // An unprefixed id may be this server's own, from before it had a shard name: the handler decides.
  if (!owner || owner->empty() || *owner == this_shard) return ServiceStatus::success();
  return ServiceStatus::error(StatusCode::FailedPrecondition, "job " + job_id + " belongs to shard " + *owner);
}

}  // namespace balloon::service
