#include "http/json_mapping.hpp"

#include <google/protobuf/message.h>
#include <google/protobuf/util/json_util.h>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "jobs/json_writer.hpp"

namespace balloon::http {

std::string message_to_json(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = false;  // one line: an SSE `data:` field must not span lines
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(message, &json, options);
  // Printing a valid message cannot fail (no Any fields in the API); a failure is a broken contract.
  if (!status.ok()) throw std::logic_error("cannot print " + message.GetTypeName() + " as JSON: " + status.ToString());
  return json;
}

std::string json_to_message(const std::string& json, google::protobuf::Message* message) {
  message->Clear();
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;  // a misspelt field is a mistake worth naming, not a silent default
  const auto status = google::protobuf::util::JsonStringToMessage(json, message, options);
  if (status.ok()) return "";
  std::string problem(status.message().data(), status.message().size());
  if (json.find_first_not_of(" \t\r\n") == std::string::npos) problem = "the body is empty";
  return "the body is not valid JSON for " + message->GetTypeName() + ": " + problem;
}

std::string status_code_name(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN";
  }
}

int http_status_for(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return 200;
    case grpc::StatusCode::INVALID_ARGUMENT: return 400;
    case grpc::StatusCode::UNAUTHENTICATED: return 401;
    case grpc::StatusCode::PERMISSION_DENIED: return 403;
    case grpc::StatusCode::NOT_FOUND: return 404;
    case grpc::StatusCode::FAILED_PRECONDITION: return 409;
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return 413;
    case grpc::StatusCode::CANCELLED: return 499;  // nginx's "client closed request"; no standard code fits
    case grpc::StatusCode::UNIMPLEMENTED: return 501;
    case grpc::StatusCode::UNAVAILABLE: return 503;
    default: return 500;
  }
}

std::string status_json(grpc::StatusCode code, const std::string& message, const std::string& error_details) {
  jobs::JsonWriter json;
  json.begin_object().value("code", status_code_name(code)).value("message", message);
  google::rpc::Status details;
  if (!error_details.empty() && details.ParseFromString(error_details)) {
    bool open = false;
    for (const google::protobuf::Any& detail : details.details()) {
      google::rpc::BadRequest bad_request;
      if (!detail.UnpackTo(&bad_request)) continue;
      for (const google::rpc::BadRequest::FieldViolation& violation : bad_request.field_violations()) {
        if (!open) json.begin_array("fields");
        open = true;
        json.begin_object().value("field", violation.field()).value("description", violation.description()).end_object();
      }
    }
    if (open) json.end_array();
  }
  json.end_object();
  return json.str();
}

std::string error_body(grpc::StatusCode code, const std::string& message, const std::string& error_details) {
  return "{\"error\":" + status_json(code, message, error_details) + "}";
}

}  // namespace balloon::http
