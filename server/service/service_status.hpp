#pragma once
/// The outcome of a service call, independent of any transport. The gRPC adapter maps it onto
/// grpc::Status; the codes mirror the ones the API documents.
#include <string>

namespace balloon::service {

enum class StatusCode {
  Ok,
  InvalidArgument,     ///< bad mesh, material or option
  NotFound,            ///< no such job or material (or not the caller's)
  ResourceExhausted,   ///< queue full, mesh or message over a limit
  Unauthenticated,     ///< missing or unknown token
  PermissionDenied,    ///< e.g. deleting a preset
  FailedPrecondition,  ///< e.g. the result of an unfinished job
  Unimplemented,       ///< a job kind that does not exist yet
  Unavailable,         ///< shutting down
  Cancelled,           ///< the stream ended because the caller or the server went away
  Internal,            ///< a bug or a store failure
};

struct ServiceStatus {
  StatusCode code = StatusCode::Ok;
  std::string message;

  bool ok() const { return code == StatusCode::Ok; }
  static ServiceStatus success() { return {}; }
  static ServiceStatus error(StatusCode code, std::string message) { return {code, std::move(message)}; }
};

}  // namespace balloon::service
