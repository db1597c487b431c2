#pragma once
/// The outcome of a service call, independent of any transport. The gRPC adapter maps it onto
/// grpc::Status; the codes mirror the ones the API documents.
#include <string>
#include <vector>

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

/// One bad request field: clients find their input by `field`, never by the wording of the message.
struct FieldViolation {
  std::string field;        ///< proto field path: "design.thickness_mm" (relative to the JobSpec), "material.name"
  std::string description;  ///< why, in plain words
};

struct ServiceStatus {
  StatusCode code = StatusCode::Ok;
  std::string message;
  /// The request fields at fault (sent as a google.rpc.BadRequest in the gRPC status details); may be empty.
  std::vector<FieldViolation> fields = {};

  bool ok() const { return code == StatusCode::Ok; }
  static ServiceStatus success() { return {}; }
  static ServiceStatus error(StatusCode code, std::string message) { return {code, std::move(message)}; }
  /// INVALID_ARGUMENT about one field: `message` is both the status message and the violation's description.
  static ServiceStatus bad_field(std::string field, std::string message) {
    return field_error(StatusCode::InvalidArgument, std::move(field), std::move(message));
  }
  /// A status of another code that one field caused (a resolution over the server's limit, a preset's name).
  static ServiceStatus field_error(StatusCode code, std::string field, std::string message) {
    ServiceStatus status{code, message};
    status.fields.push_back({std::move(field), std::move(message)});
    return status;
  }
  /// INVALID_ARGUMENT about several fields (at least one): the message is the first one's description.
  static ServiceStatus bad_fields(std::vector<FieldViolation> violations) {
    ServiceStatus status{StatusCode::InvalidArgument, violations.front().description};
    status.fields = std::move(violations);
    return status;
  }
  /// This status with `prefix` put before every field path ("design." before "thickness_mm").
  ServiceStatus under(const std::string& prefix) && {
    for (FieldViolation& violation : fields) violation.field = prefix + violation.field;
    return std::move(*this);
  }
};

}  // namespace balloon::service
