#include "contract/job_result_files.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "contract/curve_files.hpp"
#include "contract/report_json.hpp"

namespace balloon::contract {
namespace {

namespace v1 = balloon::v1;

std::string number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
}

}  // namespace

std::string result_mesh_extension(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_STL: return "stl";
    case v1::MESH_FORMAT_PLY: return "ply";
    default: return "obj";
  }
}

std::string result_report_json(const v1::JobResult& result) {
  switch (result.report_case()) {
    case v1::JobResult::kSimulateReport: return report_json(result.simulate_report());
    case v1::JobResult::kDesignReport: return report_json(result.design_report());
    case v1::JobResult::kFitReport: return report_json(result.fit_report());
    case v1::JobResult::kCurveReport: return report_json(result.curve_report());
    case v1::JobResult::REPORT_NOT_SET: break;
  }
  return "{}\n";
}

std::string convergence_csv(const v1::ConvergenceLog& log) {
  std::string csv = "time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n";
  const int rows = std::min({log.time_s_size(), log.iteration_size(), log.avg_error_mm_size(),
                             log.max_error_mm_size(), log.residual_norm_size()});
  for (int i = 0; i < rows; ++i)
    csv += number(log.time_s(i)) + "," + std::to_string(log.iteration(i)) + "," + number(log.avg_error_mm(i)) + "," +
           number(log.max_error_mm(i)) + "," + number(log.residual_norm(i)) + "\n";
  return csv;
}

std::vector<JobResultFile> job_result_files(const v1::JobResult& result) {
  std::vector<JobResultFile> files;
  if (result.kind() == v1::JOB_KIND_FIT_MATERIAL) {
    files.push_back({"report.json", result_report_json(result)});
    files.push_back({"fit.svg", result.fit_report().plot_svg()});
    return files;
  }
  const std::string extension = result_mesh_extension(result.rest_mesh().format());
  files.push_back({"rest." + extension, result.rest_mesh().data()});
  files.push_back({"inflated." + extension, result.inflated_mesh().data()});
  if (result.kind() == v1::JOB_KIND_DESIGN && !result.mold_mesh().data().empty())
    files.push_back({"mold.stl", result.mold_mesh().data()});
  files.push_back({"report.json", result_report_json(result)});
  if (result.kind() == v1::JOB_KIND_DESIGN)
    files.push_back({"convergence.csv", convergence_csv(result.design_report().convergence())});
  if (result.kind() == v1::JOB_KIND_CURVE) {
    files.push_back({"curve.csv", curve_csv(result.curve_report())});
    files.push_back({"curve.svg", curve_svg(result.curve_report())});
  }
  return files;
}

}  // namespace balloon::contract
