// Service-level tests: a real balloon-server on 127.0.0.1 with an ephemeral port, driven through the
// generated gRPC stub exactly as any client would.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_io.hpp"
#include "server_process.hpp"
#include "scratch_dir.hpp"

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;
using Clock = std::chrono::steady_clock;

std::string sphere_obj(int subdivisions, double radius_mm = 10.0) {
  return write_mesh_to_memory(make_icosphere(radius_mm, subdivisions), "obj");
}

v1::SubmitJobRequest simulate_request(const std::string& obj, double volume_ratio, const std::string& material = "latex") {
  v1::SubmitJobRequest request;
  v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();
  job->mutable_rest_mesh()->set_data(obj);
  job->mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  if (material.find(':') == std::string::npos)
    job->mutable_material()->set_name(material);
  else
    job->mutable_material()->set_spec(material);
  job->set_thickness_mm(0.5);
  job->set_volume_ratio(volume_ratio);
  return request;
}

grpc::Status submit(v1::BalloonService::Stub& stub, const v1::SubmitJobRequest& request, std::string* job_id,
                    const std::string& token = "") {
  grpc::ClientContext context;
  add_token(context, token);
  v1::SubmitJobResponse reply;
  const grpc::Status status = stub.SubmitJob(&context, request, &reply);
  if (status.ok()) *job_id = reply.job().id();
  return status;
}

v1::Job get_job(v1::BalloonService::Stub& stub, const std::string& job_id, const std::string& token = "") {
  grpc::ClientContext context;
  add_token(context, token);
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  const grpc::Status status = stub.GetJob(&context, request, &job);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return job;
}

/// Polls GetJob until `state` (or a final state), at most `timeout_s`.
v1::Job wait_for(v1::BalloonService::Stub& stub, const std::string& job_id, v1::JobState state, double timeout_s,
                 const std::string& token = "") {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  v1::Job job;
  do {
    job = get_job(stub, job_id, token);
    if (job.state() == state) return job;
    if (job.state() == v1::JOB_STATE_COMPLETED || job.state() == v1::JOB_STATE_FAILED ||
        job.state() == v1::JOB_STATE_CANCELLED)
      return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  } while (Clock::now() < deadline);
  return job;
}

TEST(Service, SubmitWatchResultRoundTripStreamsDecodableIntermediateMeshes) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "2"});
  auto stub = server.stub();
  // Pressure control walks the volume path in several steps: several shape-carrying progress events.
  v1::SubmitJobRequest request = simulate_request(sphere_obj(3), 1.0, "neo-hookean:mu=0.3");
  request.mutable_spec()->mutable_simulate()->set_pressure_kpa(18.0);
  std::string job_id;
  ASSERT_TRUE(submit(*stub, request, &job_id).ok());

  grpc::Status status;
  const std::vector<v1::JobEvent> events = watch_all(*stub, job_id, &status);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(events.size(), 3u);
  EXPECT_EQ(events.back().state(), v1::JOB_STATE_COMPLETED);
  EXPECT_TRUE(events.back().converged());

  int progress_events = 0, mesh_events = 0;
  std::vector<std::uint32_t> triangles;
  for (const v1::JobEvent& event : events) {
    EXPECT_EQ(event.job_id(), job_id);
    if (event.has_progress() && event.state() == v1::JOB_STATE_RUNNING) ++progress_events;
    if (!event.has_mesh()) continue;
    ++mesh_events;
    const v1::IntermediateMesh& mesh = event.mesh();
    if (mesh_events == 1) {
      ASSERT_GT(mesh.triangles_size(), 0) << "the first mesh event carries the connectivity";
      triangles.assign(mesh.triangles().begin(), mesh.triangles().end());
    } else {
      EXPECT_EQ(mesh.triangles_size(), 0) << "later mesh events carry positions only";
    }
    ASSERT_EQ(mesh.vertex_count(), 642u);
    ASSERT_EQ(mesh.positions_mm_size(), 3 * 642);
    TriMesh decoded;
    decoded.vertices.resize(642, 3);
    for (int i = 0; i < mesh.positions_mm_size(); ++i) decoded.vertices.data()[i] = mesh.positions_mm(i);
    decoded.faces.resize(static_cast<Eigen::Index>(triangles.size() / 3), 3);
    for (std::size_t i = 0; i < triangles.size(); ++i) decoded.faces.data()[i] = static_cast<int>(triangles[i]);
    const Result<MeshCheckReport> check = validate_balloon_mesh(decoded);
    ASSERT_TRUE(check.ok()) << check.error();
    EXPECT_FALSE(check->flipped);
    EXPECT_GT(check->volume_mm3, 4000.0);  // inflated beyond the rest volume 4153 mm^3
  }
  EXPECT_GE(progress_events, 1);
  EXPECT_GE(mesh_events, 1);

  grpc::ClientContext context;
  v1::GetResultRequest result_request;
  result_request.set_job_id(job_id);
  result_request.set_format(v1::MESH_FORMAT_PLY);
  v1::JobResult result;
  ASSERT_TRUE(stub->GetResult(&context, result_request, &result).ok());
  EXPECT_TRUE(result.converged());
  const Result<TriMesh> inflated = read_mesh_from_memory(result.inflated_mesh().data(), "ply");
  ASSERT_TRUE(inflated.ok()) << inflated.error();
  EXPECT_EQ(inflated->vertex_count(), 642);
  EXPECT_NEAR(result.simulate_report().pressure_kpa(), 18.0, 1e-9) << result.simulate_report().DebugString();
  const Result<TriMesh> rest = read_mesh_from_memory(result.rest_mesh().data(), "ply");
  ASSERT_TRUE(rest.ok());
  EXPECT_NEAR(rest->vertices.row(0).norm(), 10.0, 1e-5);  // PLY is read in float32
}

TEST(Service, BadInputsGetTheRightStatusAndTheServerKeepsServing) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1", "--max-mesh-vertices", "1000", "--max-message-mb", "1"});
  auto stub = server.stub();
  const std::string good = sphere_obj(2);
  struct Case {
    const char* name;
    v1::SubmitJobRequest request;
    grpc::StatusCode code;
    const char* needle;
  };
  std::vector<Case> cases;
  cases.push_back({"garbage mesh bytes", simulate_request("\x01\x02garbage\xff", 2.0), grpc::StatusCode::INVALID_ARGUMENT, "rest_mesh"});
  cases.push_back({"open mesh",
                   simulate_request("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 2 3 4\n", 2.0),
                   grpc::StatusCode::INVALID_ARGUMENT, "open"});
  {
    std::string nan_mesh = good;
    nan_mesh.replace(nan_mesh.find("v ") + 2, 1, "nan ");
    cases.push_back({"NaN coordinates", simulate_request(nan_mesh, 2.0), grpc::StatusCode::INVALID_ARGUMENT, "rest_mesh"});
  }
  cases.push_back({"unknown material", simulate_request(good, 2.0, "unobtainium"), grpc::StatusCode::INVALID_ARGUMENT, "unobtainium"});
  {
    v1::SubmitJobRequest negative = simulate_request(good, 2.0);
    negative.mutable_spec()->mutable_simulate()->set_thickness_mm(-0.5);
    cases.push_back({"negative thickness", negative, grpc::StatusCode::INVALID_ARGUMENT, "thickness"});
  }
  cases.push_back({"10x the vertex limit", simulate_request(sphere_obj(5), 2.0), grpc::StatusCode::RESOURCE_EXHAUSTED, "limit"});
  {
    v1::SubmitJobRequest oversized = simulate_request(good, 2.0);
    oversized.mutable_spec()->mutable_simulate()->mutable_rest_mesh()->mutable_data()->append(2 << 20, '#');
    cases.push_back({"oversized message", oversized, grpc::StatusCode::RESOURCE_EXHAUSTED, ""});
  }
  {
    v1::SubmitJobRequest design;
    design.mutable_spec()->mutable_design()->mutable_target_mesh()->set_data(good);
    // Design jobs run now (issue 4); one without a mesh format is refused before queueing.
    cases.push_back({"design job without a mesh format", design, grpc::StatusCode::INVALID_ARGUMENT, "target_mesh"});
  }
  cases.push_back({"empty spec", v1::SubmitJobRequest(), grpc::StatusCode::INVALID_ARGUMENT, "spec"});
  for (const Case& c : cases) {
    std::string job_id;
    const grpc::Status status = submit(*stub, c.request, &job_id);
    EXPECT_EQ(status.error_code(), c.code) << c.name << ": " << status.error_message();
    EXPECT_NE(status.error_message().find(c.needle), std::string::npos) << c.name << ": " << status.error_message();
  }
  // Unknown jobs and unfinished results.
  {
    grpc::ClientContext context;
    v1::GetJobRequest request;
    request.set_job_id("j-0000000000000000");
    v1::Job job;
    EXPECT_EQ(stub->GetJob(&context, request, &job).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // Still serving: a good job completes.
  std::string job_id;
  ASSERT_TRUE(submit(*stub, simulate_request(good, 2.0), &job_id).ok());
  EXPECT_EQ(wait_for(*stub, job_id, v1::JOB_STATE_COMPLETED, 30).state(), v1::JOB_STATE_COMPLETED);
}

TEST(Service, TokensAreRequiredAndTenantsAreIsolated) {
  ScratchDir scratch;
  std::ofstream(scratch.file("tokens")) << "# tenant token\nalice alice-token-0123456789\nbob bob-token-0123456789ab\n";
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1", "--token-file", scratch.file("tokens")});
  auto stub = server.stub();
  const v1::SubmitJobRequest request = simulate_request(sphere_obj(2), 2.0);
  std::string job_id;
  EXPECT_EQ(submit(*stub, request, &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(submit(*stub, request, &job_id, "wrong-token-0123456789").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  ASSERT_TRUE(submit(*stub, request, &job_id, "alice-token-0123456789").ok());
  // Bob cannot see Alice's job: it does not exist for him.
  grpc::ClientContext context;
  add_token(context, "bob-token-0123456789ab");
  v1::GetJobRequest get;
  get.set_job_id(job_id);
  v1::Job job;
  EXPECT_EQ(stub->GetJob(&context, get, &job).error_code(), grpc::StatusCode::NOT_FOUND);
  // Presets are readable by all; deleting one is refused.
  grpc::ClientContext delete_context;
  add_token(delete_context, "bob-token-0123456789ab");
  v1::DeleteMaterialRequest remove;
  remove.set_name("latex");
  v1::DeleteMaterialResponse removed;
  EXPECT_EQ(stub->DeleteMaterial(&delete_context, remove, &removed).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  server.stop(SIGTERM);
  EXPECT_EQ(server.log().find("alice-token"), std::string::npos) << "tokens must never be logged";
}

TEST(Service, FourWorkersTwentyJobsEightClientsNoneLostNoneDuplicated) {
  ScratchDir scratch;
  constexpr int CLIENTS = 8, JOBS = 20;
  {
    std::ofstream tokens(scratch.file("tokens"));
    for (int c = 0; c < CLIENTS; ++c) tokens << "client" << c << " token-of-client-" << c << "-0123456789\n";
  }
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "4", "--token-file", scratch.file("tokens")});
  const std::string mesh = sphere_obj(2);
  std::vector<std::vector<std::string>> ids(CLIENTS);
  std::atomic<int> failures{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < CLIENTS; ++c) {
    clients.emplace_back([&, c] {
      auto stub = server.stub();
      const std::string token = "token-of-client-" + std::to_string(c) + "-0123456789";
      for (int j = c; j < JOBS; j += CLIENTS) {
        std::string job_id;
        if (!submit(*stub, simulate_request(mesh, 1.5 + 0.1 * j), &job_id, token).ok()) ++failures;
        ids[static_cast<std::size_t>(c)].push_back(job_id);
      }
      for (const std::string& job_id : ids[static_cast<std::size_t>(c)])
        if (wait_for(*stub, job_id, v1::JOB_STATE_COMPLETED, 60, token).state() != v1::JOB_STATE_COMPLETED) ++failures;
    });
  }
  for (std::thread& client : clients) client.join();
  EXPECT_EQ(failures.load(), 0);
  std::set<std::string> all;
  for (int c = 0; c < CLIENTS; ++c) {
    auto stub = server.stub();
    grpc::ClientContext context;
    add_token(context, "token-of-client-" + std::to_string(c) + "-0123456789");
    v1::ListJobsResponse listed;
    ASSERT_TRUE(stub->ListJobs(&context, v1::ListJobsRequest(), &listed).ok());
    std::set<std::string> seen;
    for (const v1::Job& job : listed.jobs()) {
      seen.insert(job.id());
      EXPECT_EQ(job.state(), v1::JOB_STATE_COMPLETED);
      EXPECT_EQ(job.attempts(), 1) << "a job ran twice";
    }
    EXPECT_EQ(seen, std::set<std::string>(ids[static_cast<std::size_t>(c)].begin(), ids[static_cast<std::size_t>(c)].end()))
        << "client " << c << " sees exactly its own jobs";
    all.insert(seen.begin(), seen.end());
  }
  EXPECT_EQ(all.size(), static_cast<std::size_t>(JOBS));
}

TEST(Service, CancellingARunningJobIsImmediateAndFreesTheWorker) {
  ScratchDir scratch;
  ServerProcess server(scratch.file("jobs.db"), {"--workers", "1"});
  auto stub = server.stub();
  std::string long_job;
  ASSERT_TRUE(submit(*stub, simulate_request(sphere_obj(5), 125.0), &long_job).ok());
  ASSERT_EQ(wait_for(*stub, long_job, v1::JOB_STATE_RUNNING, 30).state(), v1::JOB_STATE_RUNNING);
  const auto cancelled_at = Clock::now();
  grpc::ClientContext context;
  v1::CancelJobRequest cancel;
  cancel.set_job_id(long_job);
  v1::Job job;
  ASSERT_TRUE(stub->CancelJob(&context, cancel, &job).ok());
  const v1::Job after = wait_for(*stub, long_job, v1::JOB_STATE_CANCELLED, 1.0);
  EXPECT_EQ(after.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - cancelled_at).count(), 1.0);
  // The only worker is free again: a small job starts soon (one solver iteration of the big one at most).
  std::string small_job;
  ASSERT_TRUE(submit(*stub, simulate_request(sphere_obj(2), 2.0), &small_job).ok());
  EXPECT_EQ(wait_for(*stub, small_job, v1::JOB_STATE_COMPLETED, 10).state(), v1::JOB_STATE_COMPLETED);
}

TEST(Service, KillNineMidJobThenRestartCompletesTheJobAndKeepsEarlierResults) {
  ScratchDir scratch;
  const std::string db = scratch.file("jobs.db");
  std::string first_job, long_job;
  {
    ServerProcess server(db, {"--workers", "1"});
    auto stub = server.stub();
    ASSERT_TRUE(submit(*stub, simulate_request(sphere_obj(2), 3.0), &first_job).ok());
    ASSERT_EQ(wait_for(*stub, first_job, v1::JOB_STATE_COMPLETED, 30).state(), v1::JOB_STATE_COMPLETED);
    ASSERT_TRUE(submit(*stub, simulate_request(sphere_obj(5), 125.0), &long_job).ok());
    ASSERT_EQ(wait_for(*stub, long_job, v1::JOB_STATE_RUNNING, 30).state(), v1::JOB_STATE_RUNNING);
    EXPECT_EQ(server.stop(SIGKILL), 128 + SIGKILL);
  }
  ServerProcess restarted(db, {"--workers", "1"});
  auto stub = restarted.stub();
  const v1::Job recovered = wait_for(*stub, long_job, v1::JOB_STATE_COMPLETED, 60);
  EXPECT_EQ(recovered.state(), v1::JOB_STATE_COMPLETED);
  EXPECT_EQ(recovered.attempts(), 2);
  grpc::ClientContext context;
  v1::GetResultRequest request;
  request.set_job_id(first_job);
  v1::JobResult result;
  ASSERT_TRUE(stub->GetResult(&context, request, &result).ok());
  EXPECT_TRUE(result.converged());
  EXPECT_DOUBLE_EQ(result.simulate_report().target_volume_ratio(), 3.0);
  EXPECT_NEAR(result.simulate_report().volume_ratio(), 3.0, 1e-6) << result.simulate_report().DebugString();
}

TEST(Service, SigtermStopsPromptlyAndRequeuesTheRunningJob) {
  ScratchDir scratch;
  const std::string db = scratch.file("jobs.db");
  std::string job_id;
  {
    ServerProcess server(db, {"--workers", "1"});
    auto stub = server.stub();
    ASSERT_TRUE(submit(*stub, simulate_request(sphere_obj(5), 125.0), &job_id).ok());
    ASSERT_EQ(wait_for(*stub, job_id, v1::JOB_STATE_RUNNING, 30).state(), v1::JOB_STATE_RUNNING);
    const auto start = Clock::now();
    EXPECT_EQ(server.stop(SIGTERM), 0);
    EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 10.0);
  }
  ServerProcess restarted(db, {"--workers", "1"});
  auto stub = restarted.stub();
  EXPECT_EQ(wait_for(*stub, job_id, v1::JOB_STATE_COMPLETED, 60).state(), v1::JOB_STATE_COMPLETED);
}

}  // namespace
}  // namespace balloon::testing
