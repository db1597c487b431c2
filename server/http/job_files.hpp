#pragma once
/// The downloadable files of a finished job (GET /api/v1/jobs/{id}/files/{file}): the files
/// contract::job_result_files makes from its result with meshes in OBJ (the same names and bytes the CLI
/// writes): rest.obj, inflated.obj, mold.stl, report.json, convergence.csv, and fit.svg for a material fit.
/// Kept apart from the HTTP code (httplib's <resolv.h> defines `_res`, which breaks Eigen's headers).
#include <string>

#include <grpcpp/support/status.h>

#include "balloon/v1/balloon.pb.h"

namespace balloon::http {

/// The file names a job may have, for messages: "rest.obj, inflated.obj, mold.stl, report.json,
/// convergence.csv or fit.svg".
extern const char* const JOB_FILE_NAMES;

/// True for one of JOB_FILE_NAMES.
bool is_job_file_name(const std::string& name);

/// One file's bytes and media type, or why there is none.
struct JobFile {
  grpc::Status status;       ///< OK, or NOT_FOUND (a file this job does not have)
  std::string bytes;         ///< the file (OK only)
  std::string content_type;  ///< its media type (OK only)
};

/// The file `name` of the job whose result is `result` (meshes in OBJ).
JobFile job_file(const balloon::v1::JobResult& result, const std::string& name);

}  // namespace balloon::http
