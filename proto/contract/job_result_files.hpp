#pragma once
/// The files of a finished job, made from its JobResult alone: the one definition behind
/// `balloon design --out-dir`, `balloon jobs result --out-dir` and GET /api/v1/jobs/{id}/files/{file},
/// so every path writes the same names with the same bytes.
#include <string>
#include <vector>

#include "balloon/v1/balloon.pb.h"

namespace balloon::contract {

/// One file: its name in the directory and its bytes.
struct JobResultFile {
  std::string name;
  std::string bytes;
};

/// The extension of a result mesh in `format`: "obj", "stl", "ply" ("obj" for UNSPECIFIED).
std::string result_mesh_extension(balloon::v1::MeshFormat format);

/// The files of `result`, in this order (EXT from the result meshes' format, result_mesh_extension):
///   design:        rest.EXT, inflated.EXT, mold.stl (only when the server built a mold), report.json,
///                  convergence.csv
///   simulate:      rest.EXT, inflated.EXT, report.json
///   curve:         rest.EXT, inflated.EXT (the last converged point), report.json, curve.csv, curve.svg
///                  (contract/curve_files)
///   fit-material:  report.json, fit.svg
/// report.json is report_json() of the result's report; convergence.csv is convergence_csv() of the
/// design report's log; mold.stl is the server's mold_mesh as it came.
std::vector<JobResultFile> job_result_files(const balloon::v1::JobResult& result);

/// The report of `result` as report.json (report_json); "{}\n" for a result without one.
std::string result_report_json(const balloon::v1::JobResult& result);

/// The convergence log as CSV: header `time_s,iteration,avg_error_mm,max_error_mm,residual_norm`, one row
/// per sample, numbers as in report.json.
std::string convergence_csv(const balloon::v1::ConvergenceLog& log);

}  // namespace balloon::contract
