// Service-level tests of the material-fit and design job kinds: a real balloon-server on 127.0.0.1 with an
// ephemeral port, driven through the generated gRPC stub.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "contract/job_result_files.hpp"
#include "jobs/fit_job.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_io.hpp"
#include "server_process.hpp"
#include "service/job_reports.hpp"
#include "scratch_dir.hpp"

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

v1::SubmitJobRequest treloar_fit_request(const std::string& model, const std::string& name) {
  v1::SubmitJobRequest request;
  v1::FitMaterialJob* job = request.mutable_spec()->mutable_fit_material();
  v1::MeasurementSet* set = job->add_data();
  set->set_csv(read_text(std::string(BALLOON_TEST_DATA_DIR) + "/materials/treloar1944_et.csv"));
  set->set_test("equibiaxial");
  job->set_model(model);
  job->set_name(name);
  return request;
}

grpc::Status submit_job(v1::BalloonService::Stub& stub, const v1::SubmitJobRequest& request, std::string* job_id) {
  grpc::ClientContext context;
  v1::SubmitJobResponse reply;
  const grpc::Status status = stub.SubmitJob(&context, request, &reply);
  if (status.ok()) *job_id = reply.job().id();
  return status;
}

/// Submits `request`, follows it to its end, which must be COMPLETED, and fetches its result.
::testing::AssertionResult run_to_result(v1::BalloonService::Stub& stub, const v1::SubmitJobRequest& request,
                                         v1::JobResult* result) {
  std::string job_id;
  const grpc::Status submitted = submit_job(stub, request, &job_id);
  if (!submitted.ok()) return ::testing::AssertionFailure() << "submit: " << submitted.error_message();
  grpc::Status status;
  const std::vector<v1::JobEvent> events = watch_all(stub, job_id, &status);
  if (!status.ok()) return ::testing::AssertionFailure() << "watch: " << status.error_message();
  if (events.empty() || events.back().state() != v1::JOB_STATE_COMPLETED)
    return ::testing::AssertionFailure() << "not completed: " << (events.empty() ? "no events" : events.back().message());
  grpc::ClientContext context;
  v1::GetResultRequest result_request;
  result_request.set_job_id(job_id);
  const grpc::Status got = stub.GetResult(&context, result_request, result);
  if (!got.ok()) return ::testing::AssertionFailure() << "result: " << got.error_message();
  return ::testing::AssertionSuccess();
}

TEST(ServiceJobs, FitJobFitsTreloarStoresTheMaterialAndReturnsTheReport) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();

  v1::JobResult result;
  ASSERT_TRUE(run_to_result(*stub, treloar_fit_request("hart-smith", "treloar-hs"), &result));
  EXPECT_EQ(result.kind(), v1::JOB_KIND_FIT_MATERIAL);
  EXPECT_TRUE(result.rest_mesh().data().empty()) << "a fit has no meshes";
  ASSERT_TRUE(result.has_fit_report());
  ASSERT_EQ(result.fit_report().fits_size(), 1);
  const v1::FitModelReport& fit = result.fit_report().fits(0);
  EXPECT_EQ(fit.model(), "hart-smith");
  EXPECT_EQ(fit.points(), 16);
  // The CLI measured rms 0.0189 MPa for Hart-Smith on these 16 points (tests/client/test_fit_material_command).
  EXPECT_GT(fit.rms_residual(), 0.0);
  EXPECT_LT(fit.rms_residual(), 0.03);
  ASSERT_EQ(fit.params().count("G"), 1u);
  EXPECT_GT(fit.params().at("G"), 0.0);
  EXPECT_EQ(result.fit_report().plot_svg().rfind("<svg", 0), 0u);

  // The best fit is now this tenant's material, with its provenance.
  grpc::ClientContext material_context;
  v1::GetMaterialRequest material_request;
  material_request.set_name("treloar-hs");
  v1::Material material;
  const grpc::Status found = stub->GetMaterial(&material_context, material_request, &material);
  ASSERT_TRUE(found.ok()) << found.error_message();
  EXPECT_EQ(material.spec().rfind("hart-smith:", 0), 0u) << material.spec();
  EXPECT_NE(material.description().find("sha256"), std::string::npos) << material.description();
  EXPECT_NE(material.description().find("hart-smith"), std::string::npos) << material.description();
}

// The CLI prints and plots a service fit from its report: reading the report back must give the same
// text, plot and JSON as the fit itself (all models, two sets, including any infinite standard errors).
TEST(ServiceJobs, FitReportReadsBackToTheSameTextPlotAndJson) {
  const std::string dir = std::string(BALLOON_TEST_DATA_DIR) + "/materials/";
  std::vector<jobs::FitDataFile> files(2);
  files[0].label = "treloar1944_ut.csv";
  files[0].csv_text = read_text(dir + "treloar1944_ut.csv");
  files[0].test = "uniaxial";
  files[1].label = "treloar1944_et.csv";
  files[1].csv_text = read_text(dir + "treloar1944_et.csv");
  files[1].test = "equibiaxial";
  const Result<jobs::FitInput> input = jobs::prepare_fit(files, "all");
  ASSERT_TRUE(input.ok()) << input.error();
  const Result<jobs::FitOutcome> fitted = jobs::run_fit(*input);
  ASSERT_TRUE(fitted.ok()) << fitted.error();
  ASSERT_EQ(fitted->fits.size(), 3u);
  const std::string json = jobs::fit_report_json(*input, *fitted);
  const v1::FitReport report = service::fit_report(*input, *fitted);
  EXPECT_EQ(report.best_fit(), jobs::best_fit_index(*fitted));

  Result<jobs::FitOutcome> read = service::fit_outcome_from_report(*input, report);
  ASSERT_TRUE(read.ok()) << read.error();
  read->time_s = fitted->time_s;
  EXPECT_EQ(jobs::fit_report_json(*input, *read), json);
  EXPECT_EQ(jobs::fit_summary_text(*input, *read), jobs::fit_summary_text(*input, *fitted));
  EXPECT_EQ(jobs::fit_plot_svg(*input, *read), jobs::fit_plot_svg(*input, *fitted));
  EXPECT_EQ(jobs::best_fit_index(*read), jobs::best_fit_index(*fitted));

  // A report that does not match the input is refused, not half-read.
  v1::FitReport one_fit;
  one_fit.add_fits()->set_model("hart-smith");
  EXPECT_FALSE(service::fit_outcome_from_report(*input, one_fit).ok());
  v1::FitReport no_sets = report;
  no_sets.mutable_fits(0)->clear_sets();
  EXPECT_FALSE(service::fit_outcome_from_report(*input, no_sets).ok());
  v1::FitReport no_constant = report;
  no_constant.mutable_fits(1)->mutable_params()->clear();
  EXPECT_FALSE(service::fit_outcome_from_report(*input, no_constant).ok());
}

// "all" on data too short for Hart-Smith's three constants fits the two laws it can and says why it left
// the third out (the whole command failed: "hart-smith: only 2 data points for the 3 parameters").
TEST(ServiceJobs, AllFitsTheLawsTheDataCanFitAndNamesTheOneItLeftOut) {
  std::vector<jobs::FitDataFile> files(1);
  files[0].label = "two.csv";
  files[0].csv_text = "stretch,nominal_stress_MPa\n1.2,0.2\n1.4,0.3\n";
  files[0].test = "uniaxial";
  const Result<jobs::FitInput> input = jobs::prepare_fit(files, "all");
  ASSERT_TRUE(input.ok()) << input.error();
  const Result<jobs::FitOutcome> fitted = jobs::run_fit(*input);
  ASSERT_TRUE(fitted.ok()) << fitted.error();
  ASSERT_EQ(fitted->fits.size(), 2u);
  EXPECT_EQ(fitted->fits[0].material.model, MaterialModel::MooneyRivlin);
  EXPECT_EQ(fitted->fits[1].material.model, MaterialModel::NeoHookean);
  ASSERT_EQ(fitted->skipped.size(), 1u);
  EXPECT_EQ(fitted->skipped[0].model, MaterialModel::HartSmith);
  EXPECT_EQ(fitted->skipped[0].reason, "only 2 data points for the 3 parameters of hart-smith");
  EXPECT_NE(jobs::fit_summary_text(*input, *fitted).find("hart-smith: not fitted: only 2 data points"), std::string::npos);
  EXPECT_NE(jobs::fit_report_json(*input, *fitted).find(R"("model":"hart-smith","skipped":"only 2 data points)"),
            std::string::npos)
      << jobs::fit_report_json(*input, *fitted);
  // Through the report (what the CLI reads back from a server): the same outcome.
  const v1::FitReport report = service::fit_report(*input, *fitted);
  ASSERT_EQ(report.skipped_size(), 1);
  EXPECT_EQ(report.skipped(0).model(), "hart-smith");
  Result<jobs::FitOutcome> read = service::fit_outcome_from_report(*input, report);
  ASSERT_TRUE(read.ok()) << read.error();
  read->time_s = fitted->time_s;
  EXPECT_EQ(jobs::fit_summary_text(*input, *read), jobs::fit_summary_text(*input, *fitted));
  // One model asked for by name still fails on such data, and so does "all" when no law fits.
  const Result<jobs::FitInput> hart_smith = jobs::prepare_fit(files, "hart-smith");
  ASSERT_TRUE(hart_smith.ok());
  const Result<jobs::FitOutcome> refused = jobs::run_fit(*hart_smith);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error(), "hart-smith: only 2 data points for the 3 parameters of hart-smith");
  files[0].csv_text = "stretch,nominal_stress_MPa\n1.2,0\n1.4,0\n";
  const Result<jobs::FitInput> zeros = jobs::prepare_fit(files, "all");
  ASSERT_TRUE(zeros.ok()) << zeros.error();
  const Result<jobs::FitOutcome> none = jobs::run_fit(*zeros);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().rfind("no law fits this data (hart-smith: ", 0), 0u) << none.error();
}

TEST(ServiceJobs, BadFitJobsAreRefusedAtSubmitAndPresetsCannotBeOverwritten) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();
  std::string job_id;

  grpc::Status status = submit_job(*stub, treloar_fit_request("hart-smith", "latex"), &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << status.error_message();
  EXPECT_NE(status.error_message().find("preset"), std::string::npos) << status.error_message();

  status = submit_job(*stub, treloar_fit_request("ogden", ""), &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();

  v1::SubmitJobRequest empty_csv = treloar_fit_request("neo-hookean", "");
  empty_csv.mutable_spec()->mutable_fit_material()->mutable_data(0)->set_csv("");
  status = submit_job(*stub, empty_csv, &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();

  v1::SubmitJobRequest no_data = treloar_fit_request("neo-hookean", "");
  no_data.mutable_spec()->mutable_fit_material()->clear_data();
  status = submit_job(*stub, no_data, &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();

  // Nothing was queued, and the server still runs a good fit.
  grpc::ClientContext list_context;
  v1::ListJobsRequest list_request;
  v1::ListJobsResponse listed;
  ASSERT_TRUE(stub->ListJobs(&list_context, list_request, &listed).ok());
  EXPECT_EQ(listed.jobs_size(), 0);
  status = submit_job(*stub, treloar_fit_request("neo-hookean", ""), &job_id);
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST(ServiceJobs, DesignJobStreamsIntermediateMeshesAndReturnsAReport) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();

  v1::SubmitJobRequest request;
  v1::DesignJob* job = request.mutable_spec()->mutable_design();
  // An ellipsoid, not a sphere: the Gauss-Newton design matches a sphere in one iteration, and this test
  // needs several to see intermediate shapes streamed.
  TriMesh target = make_icosphere(10.0, 2);
  target.vertices.col(0) *= 1.3;
  job->mutable_target_mesh()->set_data(write_mesh_to_memory(target, "obj"));
  job->mutable_target_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  job->mutable_material()->set_name("latex");
  job->set_thickness_mm(0.5);
  job->set_resolution(0);  // never remesh: keep the 162-vertex sphere
  job->set_max_time_s(20.0);
  request.mutable_spec()->set_progress_mesh_every(1);
  std::string job_id;
  const grpc::Status submitted = submit_job(*stub, request, &job_id);
  ASSERT_TRUE(submitted.ok()) << submitted.error_message();

  grpc::Status status;
  const std::vector<v1::JobEvent> events = watch_all(*stub, job_id, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_FALSE(events.empty());
  ASSERT_EQ(events.back().state(), v1::JOB_STATE_COMPLETED) << events.back().message();

  int progress_events = 0, mesh_events = 0;
  std::vector<std::uint32_t> triangles;
  for (const v1::JobEvent& event : events) {
    if (event.has_progress() && event.state() == v1::JOB_STATE_RUNNING) ++progress_events;
    if (!event.has_mesh()) continue;
    ++mesh_events;
    const v1::IntermediateMesh& mesh = event.mesh();
    if (mesh_events == 1) triangles.assign(mesh.triangles().begin(), mesh.triangles().end());
    ASSERT_EQ(mesh.vertex_count(), 162u);
    ASSERT_EQ(mesh.positions_mm_size(), 3 * 162);
    ASSERT_EQ(triangles.size(), 3u * 320u) << "the first mesh event carries the connectivity";
    TriMesh decoded;
    decoded.vertices.resize(162, 3);
    for (int i = 0; i < mesh.positions_mm_size(); ++i) decoded.vertices.data()[i] = mesh.positions_mm(i);
    decoded.faces.resize(320, 3);
    for (std::size_t i = 0; i < triangles.size(); ++i) decoded.faces.data()[i] = static_cast<int>(triangles[i]);
    const Result<MeshCheckReport> check = validate_balloon_mesh(decoded);
    ASSERT_TRUE(check.ok()) << check.error();
    EXPECT_GT(check->volume_mm3, 0.0);
  }
  EXPECT_GE(progress_events, 2);
  EXPECT_GE(mesh_events, 2);

  grpc::ClientContext result_context;
  v1::GetResultRequest result_request;
  result_request.set_job_id(job_id);
  result_request.set_format(v1::MESH_FORMAT_OBJ);
  v1::JobResult result;
  const grpc::Status got = stub->GetResult(&result_context, result_request, &result);
  ASSERT_TRUE(got.ok()) << got.error_message();
  EXPECT_EQ(result.kind(), v1::JOB_KIND_DESIGN);
  ASSERT_TRUE(result.has_design_report());
  const v1::DesignReport& report = result.design_report();
  const std::string json = contract::result_report_json(result);
  for (const char* key : {"avg_error_mm", "max_error_mm", "avg_error_rel", "bbox_diag_mm", "iterations", "time_s",
                          "baseline_avg_error_mm", "material", "preparation"})
    EXPECT_NE(json.find(std::string("\"") + key + "\":"), std::string::npos) << "missing " << key << " in " << json;
  ASSERT_TRUE(report.has_avg_error_mm() && report.has_max_error_mm() && report.has_baseline_avg_error_mm()) << json;
  EXPECT_GE(report.avg_error_mm(), 0.0);
  EXPECT_LE(report.avg_error_mm(), report.max_error_mm());
  // Better than the untouched target used as the rest shape (bbox diagonal of the r = 10 mm sphere ~ 34.6 mm).
  EXPECT_LT(report.avg_error_mm(), report.baseline_avg_error_mm()) << json;
  EXPECT_LE(report.time_s(), 25.0);
  EXPECT_FALSE(report.has_resumed_from_iteration()) << "it ran through";
  EXPECT_EQ(json.find("resumed_from_iteration"), std::string::npos) << json;
  // The server built the mold with the result: binary STL of the rest shape plus its tube.
  ASSERT_TRUE(report.has_mold()) << report.mold_problem();
  EXPECT_EQ(result.mold_mesh().format(), v1::MESH_FORMAT_STL);
  const Result<TriMesh> mold = read_mesh_from_memory(result.mold_mesh().data(), "stl");
  ASSERT_TRUE(mold.ok()) << mold.error();
  EXPECT_GT(mold->face_count(), 320);
  const Result<TriMesh> rest = read_mesh_from_memory(result.rest_mesh().data(), "obj");
  ASSERT_TRUE(rest.ok()) << rest.error();
  EXPECT_EQ(rest->vertex_count(), 162);
  const Result<TriMesh> inflated = read_mesh_from_memory(result.inflated_mesh().data(), "obj");
  ASSERT_TRUE(inflated.ok()) << inflated.error();
  EXPECT_EQ(inflated->vertex_count(), 162);
}

TEST(ServiceJobs, ADesignAtItsJobTimeLimitKeepsItsBestDesign) {
  // The job's time limit (not the design's own max_time_s) used to cancel the optimizer mid-iteration and
  // fail the job with nothing kept. Now the optimizer gets the limit as its budget, less time to build the
  // mold and report, and the job completes with the best design found, `time_limit`, not converged.
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();
  v1::SubmitJobRequest request;
  v1::DesignJob* job = request.mutable_spec()->mutable_design();
  TriMesh box = make_icosphere(20.0, 2);  // flat faces no inflated sheet matches: it would run on
  box.vertices = box.vertices.cwiseMax(-12.0).cwiseMin(12.0);
  job->mutable_target_mesh()->set_data(write_mesh_to_memory(box, "obj"));
  job->mutable_target_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  job->mutable_material()->set_name("silicone");
  job->set_resolution(2000);  // remeshed on the worker, within the limit
  request.mutable_spec()->set_time_limit_s(5.0);
  v1::JobResult result;
  ASSERT_TRUE(run_to_result(*stub, request, &result));
  const v1::DesignReport& report = result.design_report();
  EXPECT_EQ(report.stop_reason(), "time_limit") << report.message();
  EXPECT_FALSE(report.converged());
  EXPECT_GE(report.iterations(), 1);
  EXPECT_LT(report.time_s(), 5.0);
  ASSERT_TRUE(report.has_avg_error_mm() && report.has_baseline_avg_error_mm());
  EXPECT_LT(report.avg_error_mm(), report.baseline_avg_error_mm());
  EXPECT_FALSE(result.rest_mesh().data().empty());
}

TEST(ServiceJobs, ASimulationAndACurveAtTheirJobTimeLimitKeepWhatTheyReached) {
  // The knot with Mooney-Rivlin x8 at 100 mm runs for a minute (a bulge running along its tube). Cut at its
  // job time limit, a simulation used to fail with nothing kept; it now completes, not converged, at
  // `time_limit`, and a curve keeps the points it reached.
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();
  v1::SubmitJobRequest request;
  v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();
  job->mutable_rest_mesh()->set_data(read_text(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/knot.off"));
  job->mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OFF);
  job->mutable_material()->set_spec("mooney-rivlin:C1=0.139679,C2=0.0280028");
  job->set_size_mm(100.0);
  job->set_volume_ratio(8.0);
  request.mutable_spec()->set_time_limit_s(4.0);
  v1::JobResult result;
  ASSERT_TRUE(run_to_result(*stub, request, &result));
  EXPECT_EQ(result.simulate_report().stop_reason(), "time_limit") << result.simulate_report().message();
  EXPECT_FALSE(result.simulate_report().converged());
  EXPECT_LT(result.simulate_report().time_s(), 4.0);

  job->clear_volume_ratio();
  job->mutable_curve()->mutable_volume_ratio_range()->set_from(1.5);
  job->mutable_curve()->mutable_volume_ratio_range()->set_to(8.0);
  job->mutable_curve()->set_points(10);
  ASSERT_TRUE(run_to_result(*stub, request, &result));
  const v1::CurveReport& curve = result.curve_report();
  EXPECT_EQ(curve.stop_reason(), "time_limit") << curve.message();
  ASSERT_EQ(curve.points_size(), 10);
  EXPECT_TRUE(curve.points(0).converged()) << "the first point (x1.5) takes well under a second";
  EXPECT_FALSE(curve.points(9).converged());
}

}  // namespace
}  // namespace balloon::testing

namespace balloon::testing {
namespace {

int obj_vertex_lines(const std::string& obj) {
  int count = 0;
  std::istringstream lines(obj);
  for (std::string line; std::getline(lines, line);) count += line.rfind("v ", 0) == 0 ? 1 : 0;
  return count;
}

// GetResultRequest.inflated_mesh_only (issue 14): the CLI's `simulate --out` needs the inflated mesh only,
// so the rest mesh is neither converted nor sent; without it both come back.
TEST(ServiceJobs, InflatedMeshOnlyLeavesOutTheRestMesh) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();
  v1::SubmitJobRequest request;
  v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();
  job->mutable_rest_mesh()->set_data(write_mesh_to_memory(make_icosphere(10.0, 2), "obj"));
  job->mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  job->mutable_material()->set_spec("neo-hookean:mu=0.3");
  job->set_volume_ratio(2.0);
  std::string job_id;
  const grpc::Status submitted = submit_job(*stub, request, &job_id);
  ASSERT_TRUE(submitted.ok()) << submitted.error_message();
  grpc::Status status;
  const std::vector<v1::JobEvent> events = watch_all(*stub, job_id, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_FALSE(events.empty());
  ASSERT_EQ(events.back().state(), v1::JOB_STATE_COMPLETED) << events.back().message();

  for (const bool inflated_only : {true, false}) {
    grpc::ClientContext context;
    v1::GetResultRequest result_request;
    result_request.set_job_id(job_id);
    result_request.set_inflated_mesh_only(inflated_only);
    v1::JobResult result;
    const grpc::Status got = stub->GetResult(&context, result_request, &result);
    ASSERT_TRUE(got.ok()) << got.error_message();
    EXPECT_EQ(obj_vertex_lines(result.inflated_mesh().data()), 162) << "inflated_mesh_only " << inflated_only;
    EXPECT_EQ(obj_vertex_lines(result.rest_mesh().data()), inflated_only ? 0 : 162);
    ASSERT_TRUE(result.has_simulate_report());
    EXPECT_NEAR(result.simulate_report().volume_ratio(), 2.0, 1e-6);
  }
}

}  // namespace
}  // namespace balloon::testing
