#pragma once
/// The HTTP gateway's JSON: API messages <-> JSON with protobuf's JSON mapping (proto field names, every
/// primitive field printed), gRPC status codes -> HTTP statuses, and the error body
/// `{"error":{"code":"INVALID_ARGUMENT","message":"...","fields":[{"field":"design.thickness_mm",
/// "description":"..."}]}}`; README.md, "HTTP/JSON API".
#include <string>

#include <grpcpp/support/status_code_enum.h>

namespace google::protobuf {
class Message;
}

namespace balloon::http {

/// `message` as one line of JSON: snake_case names as in the .proto, primitive fields printed even when
/// zero, enums as names, int64 as strings, bytes as base64.
std::string message_to_json(const google::protobuf::Message& message);

/// Parses `json` into `message` (cleared first; proto or lowerCamel field names, unknown fields refused).
/// Empty when it worked, else a message naming the problem, e.g. "the body is not valid JSON for
/// balloon.v1.SubmitJobRequest: ...".
std::string json_to_message(const std::string& json, google::protobuf::Message* message);

/// The status code's canonical name: "OK", "INVALID_ARGUMENT", "NOT_FOUND", ...
std::string status_code_name(grpc::StatusCode code);

/// The HTTP status for a service status: INVALID_ARGUMENT 400, UNAUTHENTICATED 401, PERMISSION_DENIED 403,
/// NOT_FOUND 404, FAILED_PRECONDITION 409, RESOURCE_EXHAUSTED 413, CANCELLED 499, UNIMPLEMENTED 501,
/// UNAVAILABLE 503, OK 200, anything else 500.
int http_status_for(grpc::StatusCode code);

/// `{"code":"<name>","message":"<message>"}` (the payload of an error body and of the SSE end event), with
/// `"fields":[{"field":"<path>","description":"<why>"},...]` when `error_details` (a status's details: a
/// serialized google.rpc.Status) holds google.rpc.BadRequest field violations. Details that do not parse
/// are left out: the code and message still stand.
std::string status_json(grpc::StatusCode code, const std::string& message, const std::string& error_details = "");

/// `{"error":<status_json>}`.
std::string error_body(grpc::StatusCode code, const std::string& message, const std::string& error_details = "");

}  // namespace balloon::http
