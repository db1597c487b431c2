// Shard names (balloon-server --shard-name, issue 13): every job id carries its shard, and a call on
// another shard's job says which shard owns it instead of "not found".
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <regex>
#include <stdexcept>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"
#include "scratch_dir.hpp"
#include "server_process.hpp"

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;

const std::string TOKEN = "alice-token-0123456789";

v1::SubmitJobRequest small_simulate() {
  v1::SubmitJobRequest request;
  v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();
  job->mutable_rest_mesh()->set_data(write_mesh_to_memory(make_icosphere(10.0, 2), "obj"));
  job->mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  job->mutable_material()->set_name("latex");
  job->set_thickness_mm(0.5);
  job->set_volume_ratio(2.0);
  return request;
}

grpc::Status get_job(v1::BalloonService::Stub& stub, const std::string& job_id) {
  grpc::ClientContext context;
  add_token(context, TOKEN);
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  return stub.GetJob(&context, request, &job);
}

TEST(ShardRouting, JobIdsNameTheShardAndCallsOnAnotherShardsJobSayWhichShardOwnsIt) {
  ScratchDir scratch;
  std::ofstream(scratch.file("tokens")) << "alice " << TOKEN << "\n";
  ServerProcess server(scratch.file("jobs.db"),
                       {"--workers", "1", "--shard-name", "s1", "--token-file", scratch.file("tokens")});
  auto stub = server.stub();

  grpc::ClientContext submit_context;
  add_token(submit_context, TOKEN);
  v1::SubmitJobResponse submitted;
  ASSERT_TRUE(stub->SubmitJob(&submit_context, small_simulate(), &submitted).ok());
  const std::string own_id = submitted.job().id();
  EXPECT_TRUE(std::regex_match(own_id, std::regex("s1-j-[0-9a-f]{16}"))) << own_id;
  EXPECT_TRUE(get_job(*stub, own_id).ok());

  // Another shard's id: FAILED_PRECONDITION naming the owner, for every call on one job.
  const std::string foreign_id = "s2-j-0123456789abcdef";
  const grpc::Status got = get_job(*stub, foreign_id);
  EXPECT_EQ(got.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_EQ(got.error_message(), "job s2-j-0123456789abcdef belongs to shard s2");
  {
    grpc::ClientContext context;
    add_token(context, TOKEN);
    v1::CancelJobRequest request;
    request.set_job_id(foreign_id);
    v1::Job job;
    EXPECT_EQ(stub->CancelJob(&context, request, &job).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  }
  {
    grpc::ClientContext context;
    add_token(context, TOKEN);
    v1::GetResultRequest request;
    request.set_job_id(foreign_id);
    v1::JobResult result;
    EXPECT_EQ(stub->GetResult(&context, request, &result).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  }
  grpc::Status watched;
  watch_all(*stub, foreign_id, &watched, TOKEN);
  EXPECT_EQ(watched.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_NE(watched.error_message().find("belongs to shard s2"), std::string::npos) << watched.error_message();

  // A shard name with dashes parses too; ids of this shard that do not exist, unprefixed ids (a store
  // from before the flag) and strings that are no job id stay NOT_FOUND.
  EXPECT_EQ(get_job(*stub, "eu-west-2-j-0123456789abcdef").error_message(),
            "job eu-west-2-j-0123456789abcdef belongs to shard eu-west-2");
  EXPECT_EQ(get_job(*stub, "s1-j-0123456789abcdef").error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(get_job(*stub, "j-0123456789abcdef").error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(get_job(*stub, "S2-j-0123456789abcdef").error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(get_job(*stub, "s2-j-0123").error_code(), grpc::StatusCode::NOT_FOUND);
  // Authentication still comes first: no shard names leak to callers without a token.
  grpc::ClientContext anonymous;
  v1::GetJobRequest request;
  request.set_job_id(foreign_id);
  v1::Job job;
  EXPECT_EQ(stub->GetJob(&anonymous, request, &job).error_code(), grpc::StatusCode::UNAUTHENTICATED);
}

TEST(ShardRouting, BadShardNamesAndDrainTimeoutsAreRefusedAtStart) {
  ScratchDir scratch;
  for (const std::vector<std::string>& flags :
       {std::vector<std::string>{"--shard-name", "S2"}, {"--shard-name", "s_2"}, {"--shard-name", ""},
        {"--shard-name", std::string(33, 'a')}, {"--drain-timeout", "0"}, {"--drain-timeout", "-1"},
        {"--drain-timeout", "nan"}, {"--drain-timeout", "1e9"}}) {
    const std::string db = scratch.file("jobs-" + std::to_string(std::hash<std::string>()(flags[1])) + ".db");
    EXPECT_THROW(ServerProcess(db, flags), std::runtime_error) << flags[0] << " " << flags[1];
    std::ifstream log(db + ".server.log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(flags[0]), std::string::npos) << "the error names the flag: " << text;
  }
  // The longest allowed name works.
  ServerProcess server(scratch.file("ok.db"), {"--shard-name", std::string(32, 'a'), "--drain-timeout", "2.5"});
  EXPECT_EQ(server.stop(SIGTERM), 0);
}

}  // namespace
}  // namespace balloon::testing
