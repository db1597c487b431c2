// The files of a finished job (proto/contract/job_result_files): the one list behind the CLI's --out-dir
// and the HTTP files route.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "contract/job_result_files.hpp"
#include "contract/report_json.hpp"

namespace balloon::contract {
namespace {

namespace v1 = balloon::v1;

std::vector<std::string> names(const std::vector<JobResultFile>& files) {
  std::vector<std::string> list;
  for (const JobResultFile& file : files) list.push_back(file.name);
  return list;
}

v1::JobResult design_result(bool with_mold) {
  v1::JobResult result;
  result.set_kind(v1::JOB_KIND_DESIGN);
  result.mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  result.mutable_rest_mesh()->set_data("v 0 0 0\n");
  result.mutable_inflated_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  result.mutable_inflated_mesh()->set_data("v 1 1 1\n");
  v1::DesignReport* report = result.mutable_design_report();
  report->set_stop_reason("stalled");
  v1::ConvergenceLog* log = report->mutable_convergence();
  for (int i = 0; i < 2; ++i) {
    log->add_time_s(0.5 * (i + 1));
    log->add_iteration(i);
    log->add_avg_error_mm(1.0 / (i + 1));
    log->add_max_error_mm(2.0 / (i + 1));
    log->add_residual_norm(1e-9);
  }
  if (with_mold) {
    report->mutable_mold()->set_nozzle_vertex(0);
    result.mutable_mold_mesh()->set_format(v1::MESH_FORMAT_STL);
    result.mutable_mold_mesh()->set_data(std::string("solid\0bytes", 11));
  } else {
    report->set_mold_problem("no nozzle for the mold: too flat");
  }
  return result;
}

TEST(JobResultFiles, ADesignHasFiveFilesOrFourWithoutAMold) {
  const v1::JobResult result = design_result(true);
  const std::vector<JobResultFile> files = job_result_files(result);
  EXPECT_EQ(names(files),
            (std::vector<std::string>{"rest.obj", "inflated.obj", "mold.stl", "report.json", "convergence.csv"}));
  EXPECT_EQ(files[0].bytes, "v 0 0 0\n");
  EXPECT_EQ(files[2].bytes, result.mold_mesh().data()) << "the server's mold, byte for byte";
  EXPECT_EQ(files[3].bytes, report_json(result.design_report()));
  EXPECT_EQ(files[4].bytes,
            "time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n"
            "0.5,0,1,2,1e-09\n"
            "1,1,0.5,1,1e-09\n");
  EXPECT_EQ(names(job_result_files(design_result(false))),
            (std::vector<std::string>{"rest.obj", "inflated.obj", "report.json", "convergence.csv"}));
}

TEST(JobResultFiles, MeshesTakeTheirFormatsExtensionAndAFitHasItsPlot) {
  v1::JobResult simulate;
  simulate.set_kind(v1::JOB_KIND_SIMULATE);
  simulate.mutable_rest_mesh()->set_format(v1::MESH_FORMAT_STL);
  simulate.mutable_inflated_mesh()->set_format(v1::MESH_FORMAT_STL);
  simulate.mutable_simulate_report()->set_control("pressure");
  EXPECT_EQ(names(job_result_files(simulate)), (std::vector<std::string>{"rest.stl", "inflated.stl", "report.json"}));

  v1::JobResult fit;
  fit.set_kind(v1::JOB_KIND_FIT_MATERIAL);
  fit.mutable_fit_report()->set_plot_svg("<svg/>");
  fit.mutable_fit_report()->add_fits()->set_model("neo-hookean");
  const std::vector<JobResultFile> files = job_result_files(fit);
  EXPECT_EQ(names(files), (std::vector<std::string>{"report.json", "fit.svg"}));
  EXPECT_EQ(files[1].bytes, "<svg/>");
  EXPECT_EQ(files[0].bytes.rfind("{\"fits\":[{\"model\":\"neo-hookean\",", 0), 0u) << files[0].bytes;
}

}  // namespace
}  // namespace balloon::contract
