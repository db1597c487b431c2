#pragma once
/// A finished job's files in a directory: the one writer behind `balloon design --out-dir` and
/// `balloon jobs result --out-dir`; the files themselves come from contract::job_result_files, as the
/// HTTP files route serves them.
#include <string>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "result.hpp"
#include "service_connection.hpp"

namespace balloon::cli {

/// GetResult of `job_id` with meshes in `format` (only the inflated one with `inflated_mesh_only`); the
/// error carries the status (for exit_code_for).
Result<balloon::v1::JobResult> fetch_result(ServiceConnection& connection, const std::string& job_id,
                                            balloon::v1::MeshFormat format, grpc::Status* status,
                                            bool inflated_mesh_only = false);

/// Writes `result`'s files (contract::job_result_files) into `out_dir` (which exists):
///   design:        rest.EXT, inflated.EXT, mold.stl, report.json, convergence.csv
///   simulate:      rest.EXT, inflated.EXT, report.json
///   fit-material:  report.json, fit.svg
/// A design without a mold (its report says why: mold_problem) removes a stale mold.stl. Returns the
/// paths written.
Result<std::vector<std::string>> write_result_files(const balloon::v1::JobResult& result, const std::string& out_dir);

/// The problem with `out_dir` as an output directory (created if missing), or "" if it is writable.
std::string output_directory_problem(const std::string& out_dir);

}  // namespace balloon::cli
