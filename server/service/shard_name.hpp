#pragma once
/// Shard names (`balloon-server --shard-name`): every job id a shard creates starts with its name, so a
/// balancer's mistake or a failed-over tenant gets "job ... belongs to shard s2" instead of "not found".
/// Ids: "j-<16 hex>" without a shard name, "<shard>-j-<16 hex>" with one.
#include <optional>
#include <string>

#include "result.hpp"
#include "service/service_status.hpp"

namespace balloon::service {

/// Longest shard name accepted (characters).
inline constexpr std::size_t MAX_SHARD_NAME_LENGTH = 32;

/// `name` if it is 1..32 characters of [a-z0-9-] (a DNS label's alphabet, so a StatefulSet pod name
/// fits), else an error naming the problem.
Result<std::string> check_shard_name(const std::string& name);

/// `base_id` ("j-<16 hex>") prefixed with "<shard>-"; unchanged when `shard` is empty.
std::string shard_job_id(const std::string& shard, const std::string& base_id);

/// The shard a job id names: "" for an unprefixed id ("j-<16 hex>"), nullopt for a string that is not a
/// job id at all.
std::optional<std::string> shard_of_job_id(const std::string& job_id);

/// FAILED_PRECONDITION "job ID belongs to shard S" when `job_id` is a job id of another shard than
/// `this_shard`; success otherwise: ids of this shard, unprefixed ids (a store from before the server had a
/// shard name) and strings that are no job id (the handler answers NOT_FOUND).
ServiceStatus check_job_shard(const std::string& this_shard, const std::string& job_id);

}  // namespace balloon::service
