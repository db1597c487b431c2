#include "result_files.hpp"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli_output.hpp"
#include "design/balloon_design.hpp"
#include "jobs/design_job.hpp"
#include "mesh/mesh_io.hpp"

namespace balloon::cli {
namespace {

namespace v1 = balloon::v1;
using google::protobuf::Struct;
using google::protobuf::Value;

const Value* field(const Struct& object, const std::string& key) {
  const auto it = object.fields().find(key);
  return it == object.fields().end() ? nullptr : &it->second;
}

/// The convergence log from the design report's parallel arrays.
std::vector<ConvergenceSample> convergence_from_report(const Struct& report) {
  std::vector<ConvergenceSample> log;
  const Value* convergence = field(report, "convergence");
  if (convergence == nullptr || !convergence->has_struct_value()) return log;
  const Struct& columns = convergence->struct_value();
  const auto column = [&](const char* key) {
    std::vector<double> values;
    if (const Value* array = field(columns, key); array != nullptr && array->has_list_value())
      for (const Value& v : array->list_value().values()) values.push_back(v.number_value());
    return values;
  };
  const std::vector<double> time = column("time_s"), iteration = column("iteration"), avg = column("avg_error_mm"),
                            max = column("max_error_mm"), residual = column("residual_norm");
  const std::size_t rows = std::min({time.size(), iteration.size(), avg.size(), max.size(), residual.size()});
  for (std::size_t i = 0; i < rows; ++i)
    log.push_back({time[i], static_cast<int>(std::lround(iteration[i])), avg[i], max[i], residual[i]});
  return log;
}

}  // namespace

Result<v1::JobResult> fetch_result(ServiceConnection& connection, const std::string& job_id, v1::MeshFormat format,
                                   grpc::Status* status) {
  v1::GetResultRequest request;
  request.set_job_id(job_id);
  request.set_format(format);
  v1::JobResult result;
  grpc::ClientContext context;
  connection.prepare(context);
  *status = connection.stub().GetResult(&context, request, &result);
  if (!status->ok()) return fail(status->error_message());
  return result;
}

std::string output_directory_problem(const std::string& out_dir) {
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  if (error || !std::filesystem::is_directory(out_dir)) return "--out-dir: cannot create directory '" + out_dir + "'";
  if (::access(out_dir.c_str(), W_OK) != 0) return "--out-dir: directory '" + out_dir + "' is not writable";
  return "";
}

Result<std::vector<std::string>> write_result_files(const v1::JobResult& result, const std::string& out_dir,
                                                    const std::string& extension, const std::string& command) {
  const std::filesystem::path directory(out_dir);
  std::vector<std::string> written;
  const auto write = [&](const std::string& name, const std::string& bytes) -> std::string {
    const std::string path = (directory / name).string();
    Result<bool> done = write_file_atomically(path, bytes);
    if (!done) return name + ": " + done.error();
    written.push_back(path);
    return "";
  };
  std::string problem;
  if (result.kind() != v1::JOB_KIND_FIT_MATERIAL) {
    if (problem = write("rest." + extension, result.rest_mesh().data()); !problem.empty()) return fail(problem);
    if (problem = write("inflated." + extension, result.inflated_mesh().data()); !problem.empty()) return fail(problem);
  }
  if (problem = write("report.json", result.report_json() + "\n"); !problem.empty()) return fail(problem);
  if (result.kind() != v1::JOB_KIND_DESIGN) return written;

  Struct report;
  if (!google::protobuf::util::JsonStringToMessage(result.report_json(), &report).ok())
    return fail("the service returned an unreadable report");
  if (problem = write("convergence.csv", jobs::convergence_csv(convergence_from_report(report))); !problem.empty())
    return fail(problem);
  // The mold is built here from the stored rest mesh with the tube the job chose (jobs::mold_from_report
  // is the one place that builds it, for the web gateway too), since the store keeps meshes and the report only.
  if (const Value* mold = field(report, "mold"); mold != nullptr && mold->has_struct_value()) {
    Result<TriMesh> rest = read_mesh_from_memory(result.rest_mesh().data(), extension);
    if (!rest) return fail("rest mesh from the service: " + rest.error());
    Result<TriMesh> built = jobs::mold_from_report(*rest, result.report_json());
    if (!built) {
      std::fprintf(stderr, "balloon %s: warning: mold.stl not written: %s\n", command.c_str(), built.error().c_str());
    } else if (problem = write("mold.stl", write_mesh_to_memory(*built, "stl")); !problem.empty()) {
      return fail(problem);
    }
  } else {
    std::error_code ignored;
    std::filesystem::remove(directory / "mold.stl", ignored);  // never leave a stale mold from an earlier run
  }
  return written;
}

}  // namespace balloon::cli
