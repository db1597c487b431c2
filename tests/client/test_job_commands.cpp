// `balloon submit`, `balloon jobs ...` and `balloon materials ...` against the embedded server, from outside.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "cli_test_support.hpp"

namespace balloon::testing {
namespace {

TEST(JobCommands, SubmitWatchResultThroughTheEmbeddedServer) {
  ScratchDir scratch;
  ASSERT_EQ(run_balloon(scratch, {"mesh", "sphere", "--radius", "10", "--subdivisions", "2", "--out", scratch.file("s.obj")})
                .exit_code,
            0);
  const ProcessResult submitted =
      run_balloon(scratch, {"submit", scratch.file("s.obj"), "--material", "latex", "--volume-ratio", "3"});
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err;
  const std::string job_id = split_lines(submitted.out).at(0);
  ASSERT_EQ(job_id.rfind("j-", 0), 0u) << job_id;

  // The submit process ran no workers: the job waits in the local store.
  const ProcessResult shown = run_balloon(scratch, {"jobs", "show", job_id, "--json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_EQ(json_field(shown.out, "state"), "\"JOB_STATE_QUEUED\"");

  const ProcessResult watched = run_balloon(scratch, {"jobs", "watch", job_id});
  EXPECT_EQ(watched.exit_code, 0) << watched.err;
  EXPECT_NE(watched.err.find("completed"), std::string::npos) << watched.err;

  const ProcessResult result = run_balloon(scratch, {"jobs", "result", job_id, "--out-dir", scratch.file("out"), "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NEAR(json_number_field(result.out, "volume_ratio"), 3.0, 1e-6);
  for (const char* name : {"rest.obj", "inflated.obj", "report.json"})
    EXPECT_TRUE(std::filesystem::exists(scratch.file(std::string("out/") + name))) << name;

  const ProcessResult listed = run_balloon(scratch, {"jobs", "list"});
  ASSERT_EQ(listed.exit_code, 0);
  EXPECT_NE(listed.out.find(job_id), std::string::npos);
  EXPECT_NE(listed.out.find("completed"), std::string::npos);

  EXPECT_EQ(run_balloon(scratch, {"jobs", "show", "j-0000000000000000"}).exit_code, 4);
  // Results of an unknown job: not found; cancel of a finished job: a no-op that succeeds.
  EXPECT_EQ(run_balloon(scratch, {"jobs", "result", "j-0000000000000000", "--out-dir", scratch.file("x")}).exit_code, 4);
  EXPECT_EQ(run_balloon(scratch, {"jobs", "cancel", job_id}).exit_code, 0);
}

TEST(JobCommands, DeleteRefusesAnUnfinishedJobAndRemovesAFinishedOne) {
  ScratchDir scratch;
  ASSERT_EQ(run_balloon(scratch, {"mesh", "sphere", "--radius", "10", "--subdivisions", "1", "--out", scratch.file("s.obj")})
                .exit_code,
            0);
  const ProcessResult submitted =
      run_balloon(scratch, {"submit", scratch.file("s.obj"), "--material", "latex", "--volume-ratio", "2"});
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err;
  const std::string job_id = split_lines(submitted.out).at(0);
  // Queued (the submit process runs no workers): refused, with the way out.
  const ProcessResult refused = run_balloon(scratch, {"jobs", "delete", job_id});
  EXPECT_EQ(refused.exit_code, 7) << refused.err;
  EXPECT_NE(refused.err.find("cancel it before deleting it"), std::string::npos) << refused.err;
  ASSERT_EQ(run_balloon(scratch, {"jobs", "cancel", job_id}).exit_code, 0);
  const ProcessResult deleted = run_balloon(scratch, {"jobs", "delete", job_id});
  EXPECT_EQ(deleted.exit_code, 0) << deleted.err;
  EXPECT_NE(deleted.out.find("deleted " + job_id), std::string::npos) << deleted.out;
  EXPECT_EQ(run_balloon(scratch, {"jobs", "show", job_id}).exit_code, 4);
  EXPECT_EQ(run_balloon(scratch, {"jobs", "delete", job_id}).exit_code, 4);
}

TEST(JobCommands, MaterialsLibrary) {
  ScratchDir scratch;
  const ProcessResult listed = run_balloon(scratch, {"materials", "list"});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_NE(listed.out.find("silicone"), std::string::npos);
  EXPECT_NE(listed.out.find("latex"), std::string::npos);

  ASSERT_EQ(run_balloon(scratch, {"materials", "put", "soft", "--spec", "neo-hookean:mu=0.2"}).exit_code, 0);
  const ProcessResult shown = run_balloon(scratch, {"materials", "show", "soft", "--json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_EQ(json_field(shown.out, "spec"), "\"neo-hookean:mu=0.2\"");
  // Where each law's sphere pressure falls as it stretches: Neo-Hookean past 7^(1/6), for good.
  const std::optional<std::string> band = json_field(shown.out, "pressure_fall");
  ASSERT_TRUE(band) << shown.out;
  EXPECT_NEAR(json_number_field(*band, "from_stretch"), std::pow(7.0, 1.0 / 6.0), 1e-6) << *band;
  EXPECT_FALSE(json_field(*band, "to_stretch")) << *band;
  const ProcessResult latex = run_balloon(scratch, {"materials", "show", "latex"});
  ASSERT_EQ(latex.exit_code, 0) << latex.err;
  EXPECT_NE(latex.out.find("its sphere pressure falls as it stretches between stretch 1.365 and 3.966 (volume "
                           "ratio 2.55 to 62.4)"),
            std::string::npos)
      << latex.out;

  // A stored material works as --material by name.
  ASSERT_EQ(run_balloon(scratch, {"mesh", "sphere", "--radius", "10", "--subdivisions", "2", "--out", scratch.file("s.obj")})
                .exit_code,
            0);
  const ProcessResult simulated =
      run_balloon(scratch, {"simulate", scratch.file("s.obj"), "--material", "soft", "--volume-ratio", "2", "--json"});
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  EXPECT_EQ(json_field(simulated.out, "material"), "\"neo-hookean:mu=0.2\"");

  EXPECT_EQ(run_balloon(scratch, {"materials", "delete", "latex"}).exit_code, 6);
  EXPECT_EQ(run_balloon(scratch, {"materials", "put", "bad", "--spec", "neo-hookean:mu=-1"}).exit_code, 2);
  EXPECT_EQ(run_balloon(scratch, {"materials", "delete", "soft"}).exit_code, 0);
  EXPECT_EQ(run_balloon(scratch, {"materials", "show", "soft"}).exit_code, 4);
}

}  // namespace
}  // namespace balloon::testing
