#include "http/job_files.hpp"

#include "contract/job_result_files.hpp"
#include "http/static_files.hpp"

namespace balloon::http {
namespace {

namespace v1 = balloon::v1;

JobFile missing(const std::string& message) { return {grpc::Status(grpc::StatusCode::NOT_FOUND, message), "", ""}; }

}  // namespace

const char* const JOB_FILE_NAMES = "rest.obj, inflated.obj, mold.stl, report.json, convergence.csv, fit.svg, curve.csv or curve.svg";

bool is_job_file_name(const std::string& name) {
  return name == "rest.obj" || name == "inflated.obj" || name == "mold.stl" || name == "report.json" ||
         name == "convergence.csv" || name == "fit.svg" || name == "curve.csv" || name == "curve.svg";
}

JobFile job_file(const v1::JobResult& result, const std::string& name) {
  const std::string job = "job " + result.job_id();
  for (contract::JobResultFile& file : contract::job_result_files(result))
    if (file.name == name) return {grpc::Status::OK, std::move(file.bytes), content_type_for(name)};
  // Why this job has no such file, in the words a user can act on.
  if (name == "rest.obj" || name == "inflated.obj")
    return missing(job + " has no " + name + " (a material fit has no meshes)");
  if (name == "mold.stl" && result.kind() != v1::JOB_KIND_DESIGN)
    return missing(job + " is not a design: mold.stl exists for designs only");
  if (name == "mold.stl") {
    const std::string problem = result.design_report().mold_problem();
    return missing(job + ": the design has no mold" + (problem.empty() ? std::string() : ": " + problem));
  }
  if (name == "convergence.csv") return missing(job + " is not a design: convergence.csv exists for designs only");
  if (name == "fit.svg") return missing(job + " is not a material fit: fit.svg exists for material fits only");
  if (name == "curve.csv" || name == "curve.svg")
    return missing(job + " is not a curve: " + name + " exists for pressure-volume curves only");
  return missing(std::string("unknown file '") + name + "': " + JOB_FILE_NAMES);
}

}  // namespace balloon::http
