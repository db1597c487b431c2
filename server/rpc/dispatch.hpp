#pragma once
/// One call of the service on behalf of a known caller, as a grpc::Status: the shard check of a job id, the
/// handler, the status mapping, and no exception escaping. Shared by the gRPC adapter (BalloonServiceImpl,
/// after it authenticates) and the in-process stub (DirectStub), so both behave alike.
#include <functional>
#include <string>

#include <grpcpp/support/status.h>

#include "service/caller.hpp"
#include "service/service_status.hpp"
#include "service/shard_name.hpp"

namespace balloon::rpc {

/// A handler status as a grpc::Status (same code, same message; its field violations, if any, as a
/// google.rpc.Status holding a google.rpc.BadRequest in the error details).
grpc::Status to_grpc_status(const service::ServiceStatus& status);

template <class Request, class Reply, class Handler>
grpc::Status dispatch(const char* method, const service::Caller& caller, const std::string& shard_name,
                      const std::function<void(const std::string&)>& log, const Request& request, Reply* reply,
                      Handler&& handler) {
  // Every call on one job (get, cancel, result, ...) first checks that the id is this shard's.
  if constexpr (requires { request.job_id(); }) {
    if (const service::ServiceStatus shard = service::check_job_shard(shard_name, request.job_id()); !shard.ok())
      return to_grpc_status(shard);
  }
  try {
    return to_grpc_status(handler(caller, request, reply));
  } catch (const std::exception& error) {
    // No exception escapes a handler: log the detail, tell the client only that it was ours.
    if (log) log(std::string(method) + ": internal error: " + error.what());
    return grpc::Status(grpc::StatusCode::INTERNAL, std::string("internal error in ") + method);
  }
}

}  // namespace balloon::rpc
