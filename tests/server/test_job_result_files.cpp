// The files of a finished job (proto/contract/job_result_files): the one list behind the CLI's --out-dir
// and the HTTP files route.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// A curve's rows: every column, an empty cell (never 0) for values never computed; report.json has them
// as null; the plot marks the extrema.
TEST(JobResultFiles, ACurveHasItsCsvAndPlot) {
  v1::JobResult curve;
  curve.set_kind(v1::JOB_KIND_CURVE);
  v1::CurveReport* report = curve.mutable_curve_report();
  const double ratios[3] = {1.5, 3.0, 6.0}, pressures[3] = {10.0, 12.5, 11.0};
  for (int i = 0; i < 3; ++i) {
    v1::CurvePointReport* point = report->add_points();
    point->set_target(ratios[i]);
    point->set_converged(true);
    point->set_volume_ratio(ratios[i]);
    point->set_pressure_kpa(pressures[i]);
    point->set_mean_stretch(std::cbrt(ratios[i]));
    point->set_max_stretch(1.25);
    point->set_unstable_modes(i == 2 ? 2 : 0);
  }
  v1::CurvePointReport* missed = report->add_points();
  missed->set_target(12.0);
  missed->set_message("no equilibrium found");
  v1::CurveExtremumReport* peak = report->add_extrema();
  peak->set_kind("maximum");
  peak->set_point(1);
  peak->set_volume_ratio(3.2);
  peak->set_pressure_kpa(12.6);
  const std::vector<JobResultFile> files = job_result_files(curve);
  ASSERT_EQ(names(files),
            (std::vector<std::string>{"rest.obj", "inflated.obj", "report.json", "curve.csv", "curve.svg"}));
  const std::string& csv = files[3].bytes;
  EXPECT_EQ(csv.rfind("volume_ratio,pressure_kpa,mean_stretch,max_stretch,unstable_modes,converged\n1.5,10,", 0), 0u)
      << csv;
  EXPECT_NE(csv.find(",1.25,0,true\n3,12.5,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",1.25,2,true\n,,,,,false\n"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  EXPECT_NE(files[2].bytes.find("\"volume_ratio\":null,\"pressure_kpa\":null,\"mean_stretch\":null,"
                                "\"max_stretch\":null,\"unstable_modes\":null"),
            std::string::npos)
      << files[2].bytes;
  const std::string& svg = files[4].bytes;
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("pressure-maximum"), std::string::npos);
  EXPECT_EQ(svg.find("pressure-minimum"), std::string::npos);
  EXPECT_NE(svg.find("max 12.6 kPa"), std::string::npos) << svg;
}

}  // namespace
}  // namespace balloon::contract
