#pragma once
/// A finished job's files in a directory: the one writer behind `balloon design --out-dir` and
/// `balloon jobs result --out-dir`, so both write the same set under the same names.
#include <string>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "result.hpp"
#include "service_connection.hpp"

namespace balloon::cli {

/// GetResult of `job_id` with meshes in `format`; the error carries the status (for exit_code_for).
Result<balloon::v1::JobResult> fetch_result(ServiceConnection& connection, const std::string& job_id,
                                            balloon::v1::MeshFormat format, grpc::Status* status);

/// Writes `result`'s files into `out_dir` (which exists), meshes with `extension` (obj, stl, ply):
///   design:        rest.EXT, inflated.EXT, mold.stl, report.json, convergence.csv
///   simulate:      rest.EXT, inflated.EXT, report.json
///   fit-material:  report.json
/// mold.stl only when the report describes a mold (a stale one is removed); a mold that cannot be built
/// is a warning on stderr for `command`, not an error. Returns the paths written.
Result<std::vector<std::string>> write_result_files(const balloon::v1::JobResult& result, const std::string& out_dir,
                                                    const std::string& extension, const std::string& command);

/// The problem with `out_dir` as an output directory (created if missing), or "" if it is writable.
std::string output_directory_problem(const std::string& out_dir);

}  // namespace balloon::cli
