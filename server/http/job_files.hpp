#pragma once
/// The downloadable files of a finished job (GET /api/v1/jobs/{id}/files/{file}), made from its stored
/// result: rest.obj and inflated.obj as stored, report.json, mold.stl built from the rest mesh and the
/// report with jobs::mold_from_report (as the CLI builds it), and fit.svg, the plot a fit report carries.
/// Kept apart from the HTTP code (httplib's <resolv.h> defines `_res`, which breaks Eigen's headers).
#include <string>

#include <grpcpp/support/status.h>

#include "balloon/v1/balloon.pb.h"

namespace balloon::http {

/// The file names a job may have, for messages: "rest.obj, inflated.obj, mold.stl, report.json or fit.svg".
extern const char* const JOB_FILE_NAMES;

/// True for one of JOB_FILE_NAMES.
bool is_job_file_name(const std::string& name);

/// One file's bytes and media type, or why there is none.
struct JobFile {
  grpc::Status status;       ///< OK, or NOT_FOUND (a file this job cannot have) / INTERNAL (unreadable stored data)
  std::string bytes;         ///< the file (OK only)
  std::string content_type;  ///< its media type (OK only)
};

/// The file `name` of the job whose result is `result` (meshes in OBJ).
JobFile job_file(const balloon::v1::JobResult& result, const std::string& name);

}  // namespace balloon::http
