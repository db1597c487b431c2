#include "field_flags.hpp"

#include <map>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"

namespace balloon::cli {
namespace {

/// "<label>: <description>". A flag replaces the field's own proto name where the description starts
/// with it ("nozzle: ...", "fit_material.name: ..."), so the field is not named twice; a file label is put
/// in front of the description as it is.
std::string labelled(const std::string& label, const std::string& field, const std::string& description) {
  if (label.empty()) return description;
  if (label.front() == '-') {
    for (const std::string& name : {field, field.substr(field.rfind('.') + 1)})
      if (description.rfind(name + ": ", 0) == 0) return label + ": " + description.substr(name.size() + 2);
  }
  return label + ": " + description;
}

std::string naming(const std::vector<jobs::FieldProblem>& problems, const std::string& file_field,
                   const std::string& file_path) {
  std::string text;
  for (const jobs::FieldProblem& problem : problems) {
    const std::string label = !file_field.empty() && problem.field == file_field ? "'" + file_path + "'"
                                                                                  : flag_for_field(problem.field);
    text += (text.empty() ? "" : "; ") + labelled(label, problem.field, problem.message);
  }
  return text;
}

}  // namespace

std::string flag_for_field(const std::string& field_path) {
  // Every job command's options by the request field each sets (design_command, simulate_request,
  // fit_material_command, job_command), and `materials put`'s --spec.
  static const std::map<std::string, std::string> FLAGS = {
      {"design.material", "--material"},
      {"design.thickness_mm", "--thickness"},
      {"design.size_mm", "--size"},
      {"design.resolution", "--resolution"},
      {"design.scale", "--scale"},
      {"design.volume_ratio", "--volume-ratio"},
      {"design.method", "--method"},
      {"design.nozzle", "--nozzle"},
      {"design.max_time_s", "--max-time"},
      {"design.tolerance_samples", "--tolerance-samples"},
      {"simulate.material", "--material"},
      {"simulate.thickness_mm", "--thickness"},
      {"simulate.size_mm", "--size"},
      {"simulate.pressure_kpa", "--pressure"},
      {"simulate.volume_ratio", "--volume-ratio"},
      {"simulate.curve.volume_ratio_range", "--volume-ratio-range"},
      {"simulate.curve.pressure_range", "--pressure-range"},
      {"simulate.curve.points", "--points"},
      {"fit_material.model", "--model"},
      {"fit_material.name", "--name"},
      {"priority", "--priority"},
      {"time_limit_s", "--time-limit"},
      {"material.spec", "--spec"},
  };
  const auto found = FLAGS.find(field_path);
  return found == FLAGS.end() ? std::string() : found->second;
}

std::vector<jobs::FieldProblem> field_violations(const grpc::Status& status) {
  std::vector<jobs::FieldProblem> problems;
  google::rpc::Status details;
  if (status.error_details().empty() || !details.ParseFromString(status.error_details())) return problems;
  for (const google::protobuf::Any& detail : details.details()) {
    google::rpc::BadRequest bad_request;
    if (!detail.UnpackTo(&bad_request)) continue;
    for (const google::rpc::BadRequest::FieldViolation& violation : bad_request.field_violations())
      problems.push_back({violation.field(), violation.description()});
  }
  return problems;
}

std::string message_naming_fields(const grpc::Status& status, const std::string& file_field,
                                  const std::string& file_path) {
  const std::vector<jobs::FieldProblem> problems = field_violations(status);
  return problems.empty() ? status.error_message() : naming(problems, file_field, file_path);
}

std::string message_naming_flags(const std::string& job, const std::vector<jobs::FieldProblem>& problems) {
  std::vector<jobs::FieldProblem> paths = problems;
  for (jobs::FieldProblem& problem : paths) problem.field = job + "." + problem.field;
  return naming(paths, "", "");
}

}  // namespace balloon::cli
