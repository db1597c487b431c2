#pragma once
/// Service errors in the words of the command line: a bad request field, named by its path in the
/// google.rpc.BadRequest of a failed call ("design.thickness_mm"), is reported as the flag that set it
/// ("--thickness: ...") or the file it carried ("'bunny.obj': ..."), never found by reading the message.
#include <string>
#include <vector>

#include <grpcpp/support/status.h>

#include "jobs/field_problem.hpp"

namespace balloon::cli {

/// The option that sets a request field: "design.thickness_mm" -> "--thickness", "priority" ->
/// "--priority", "material.spec" -> "--spec"; empty for a field no option sets.
std::string flag_for_field(const std::string& field_path);

/// The field violations of a failed call (its details: a google.rpc.Status holding a
/// google.rpc.BadRequest); empty when it carries none.
std::vector<jobs::FieldProblem> field_violations(const grpc::Status& status);

/// One line for the user: each bad field as "<flag>: <description>", or "'<file_path>': <description>"
/// for `file_field` (the request field that carried the user's file, e.g. "design.target_mesh"), joined by
/// "; "; the status message when the call names no field.
std::string message_naming_fields(const grpc::Status& status, const std::string& file_field = "",
                                  const std::string& file_path = "");

/// The local check's problems in the same form; `job` prefixes their paths ("design", "simulate").
std::string message_naming_flags(const std::string& job, const std::vector<jobs::FieldProblem>& problems);

}  // namespace balloon::cli
