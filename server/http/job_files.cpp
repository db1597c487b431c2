#include "http/job_files.hpp"

#include "http/static_files.hpp"
#include "jobs/design_job.hpp"
#include "jobs/json_reader.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon::http {
namespace {

namespace v1 = balloon::v1;

JobFile missing(const std::string& message) { return {grpc::Status(grpc::StatusCode::NOT_FOUND, message), "", ""}; }

/// The plot a material-fit report carries (fit_report_json): in the object, or in the list's first one.
Result<std::string> plot_from_fit_report(const std::string& report_json) {
  Result<jobs::JsonValue> report = jobs::parse_json(report_json);
  if (!report) return fail("the fit report: " + report.error());
  const jobs::JsonValue* object = &*report;
  if (report->kind == jobs::JsonValue::Kind::Array && !report->items.empty()) object = &report->items.front();
  const jobs::JsonValue* plot = object->find("plot_svg");
  if (plot == nullptr || plot->kind != jobs::JsonValue::Kind::String) return fail("the fit report carries no plot");
  return plot->text;
}

}  // namespace

const char* const JOB_FILE_NAMES = "rest.obj, inflated.obj, mold.stl, report.json or fit.svg";

bool is_job_file_name(const std::string& name) {
  return name == "rest.obj" || name == "inflated.obj" || name == "mold.stl" || name == "report.json" ||
         name == "fit.svg";
}

JobFile job_file(const v1::JobResult& result, const std::string& name) {
  const std::string job = "job " + result.job_id();
  if (name == "rest.obj" || name == "inflated.obj") {
    const v1::MeshFile& mesh = name == "rest.obj" ? result.rest_mesh() : result.inflated_mesh();
    if (mesh.data().empty()) return missing(job + " has no " + name + " (a material fit has no meshes)");
    return {grpc::Status::OK, mesh.data(), content_type_for(name)};
  }
  if (name == "report.json") return {grpc::Status::OK, result.report_json(), "application/json"};
  if (name == "mold.stl") {
    if (result.kind() != v1::JOB_KIND_DESIGN) return missing(job + " is not a design: mold.stl exists for designs only");
    Result<TriMesh> rest = read_mesh_from_memory(result.rest_mesh().data(), "obj");
    if (!rest)
      return {grpc::Status(grpc::StatusCode::INTERNAL, job + ": the stored rest mesh cannot be read: " + rest.error()), "", ""};
    Result<TriMesh> mold = jobs::mold_from_report(*rest, result.report_json());
    if (!mold) return missing(job + ": " + mold.error());
    return {grpc::Status::OK, write_mesh_to_memory(*mold, "stl"), content_type_for(name)};
  }
  if (name == "fit.svg") {
    if (result.kind() != v1::JOB_KIND_FIT_MATERIAL)
      return missing(job + " is not a material fit: fit.svg exists for material fits only");
    Result<std::string> plot = plot_from_fit_report(result.report_json());
    if (!plot) return missing(job + ": " + plot.error());
    return {grpc::Status::OK, std::move(*plot), content_type_for(name)};
  }
  return missing(std::string("unknown file '") + name + "': " + JOB_FILE_NAMES);
}

}  // namespace balloon::http
