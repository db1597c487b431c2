#include "result_files.hpp"

#include <unistd.h>

#include <filesystem>

#include "cli_output.hpp"
#include "contract/job_result_files.hpp"

namespace balloon::cli {
namespace v1 = balloon::v1;

Result<v1::JobResult> fetch_result(ServiceConnection& connection, const std::string& job_id, v1::MeshFormat format,
                                   grpc::Status* status, bool inflated_mesh_only) {
  v1::GetResultRequest request;
  request.set_job_id(job_id);
  request.set_format(format);
  request.set_inflated_mesh_only(inflated_mesh_only);
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

Result<std::vector<std::string>> write_result_files(const v1::JobResult& result, const std::string& out_dir) {
  const std::filesystem::path directory(out_dir);
  std::vector<std::string> written;
  bool wrote_mold = false;
  for (const contract::JobResultFile& file : contract::job_result_files(result)) {
    const std::string path = (directory / file.name).string();
    Result<bool> done = write_file_atomically(path, file.bytes);
    if (!done) return fail(file.name + ": " + done.error());
    written.push_back(path);
    wrote_mold = wrote_mold || file.name == "mold.stl";
  }
  if (result.kind() == v1::JOB_KIND_DESIGN && !wrote_mold) {
    std::error_code ignored;
    std::filesystem::remove(directory / "mold.stl", ignored);  // never leave a stale mold from an earlier run
  }
  return written;
}

}  // namespace balloon::cli
