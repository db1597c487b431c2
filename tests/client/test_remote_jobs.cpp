// Remote use as people work (issue 12), from outside: global flags before or after the command, fire
// and forget (`submit KIND`, --detach), re-attaching (`jobs watch`), the same files from `jobs result` as
// from `design`, and Ctrl-C that leaves a remote job running. Against a real balloon-server process.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <optional>
#include <iterator>
#include <fstream>
#include <chrono>
#include <filesystem>
#include <memory>
#include <set>

#include "cli_test_support.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"
#include "server_process.hpp"

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;

/// A bumpy icosphere (radius ~10 mm): `subdivisions` 2 designs in about a second, 4 (2562 vertices)
/// runs long enough to be interrupted.
void write_bumpy(const std::string& path, int subdivisions) {
  TriMesh bumpy = make_icosphere(1.0, subdivisions);
  for (int i = 0; i < bumpy.vertex_count(); ++i) {
    const Eigen::Vector3d p = bumpy.vertices.row(i);
    bumpy.vertices.row(i) = 10.0 * (1.0 + 0.08 * std::sin(3 * p.x()) * std::sin(2 * p.y()) * std::cos(4 * p.z())) * p;
  }
  ASSERT_TRUE(write_mesh(bumpy, path).ok());
}

std::set<std::string> file_names(const std::string& directory) {
  std::set<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) names.insert(entry.path().filename().string());
  return names;
}

std::string read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The id in `text` after `prefix` ("j-" and 16 hex digits), or "".
std::string job_id_in(const std::string& text) {
  const auto at = text.find("j-");
  return at == std::string::npos ? "" : text.substr(at, 18);
}

int get_attempts(ServerProcess& server, const std::string& job_id) {
  grpc::ClientContext context;
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  return server.stub()->GetJob(&context, request, &job).ok() ? job.attempts() : -1;
}

class RemoteJobs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_scratch = new ScratchDir();
    write_bumpy(s_scratch->file("bumpy.obj"), 2);
    write_bumpy(s_scratch->file("bumpy4.obj"), 4);
    s_server = new ServerProcess(s_scratch->file("server.db"), {"--workers", "2"});
  }
  static void TearDownTestSuite() {
    delete s_server;
    delete s_scratch;
    s_server = nullptr;
    s_scratch = nullptr;
  }
  static ProcessResult run(const std::vector<std::string>& args) { return run_balloon(*s_scratch, args); }
  static std::string server() { return s_server->address(); }
  /// A design of the bumpy sphere (60 s budget) on the embedded server with the store `db`.
  static std::unique_ptr<RunningProcess> start_embedded_design(const std::string& db, const std::string& out_dir) {
    return start_balloon(*s_scratch, {"design", s_scratch->file("bumpy4.obj"), "--material", "silicone", "--resolution",
                                      "0", "--max-time", "60", "--db", db, "--out-dir", s_scratch->file(out_dir)});
  }

  static v1::Job get_job(const std::string& job_id) {
    grpc::ClientContext context;
    v1::GetJobRequest request;
    request.set_job_id(job_id);
    v1::Job job;
    EXPECT_TRUE(s_server->stub()->GetJob(&context, request, &job).ok()) << job_id;
    return job;
  }
  static void cancel(const std::string& job_id) {
    grpc::ClientContext context;
    v1::CancelJobRequest request;
    request.set_job_id(job_id);
    v1::Job job;
    s_server->stub()->CancelJob(&context, request, &job);
  }

  static ScratchDir* s_scratch;
  static ServerProcess* s_server;
};
ScratchDir* RemoteJobs::s_scratch = nullptr;
ServerProcess* RemoteJobs::s_server = nullptr;

TEST_F(RemoteJobs, GlobalFlagsWorkBeforeAndAfterTheCommand) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--server", server(), "jobs", "list", "--json"},
        std::vector<std::string>{"jobs", "list", "--server", server(), "--json"},
        std::vector<std::string>{"--json", "jobs", "--server=" + server(), "list"}}) {
    const ProcessResult listed = run(args);
    EXPECT_EQ(listed.exit_code, 0) << args[0] << " " << args[1] << ": " << listed.err;
    EXPECT_EQ(listed.out.rfind("{", 0), 0u) << listed.out;  // --json reached the command wherever it stood
  }
  // An unreachable --server before the command is used, not ignored: exit 5.
  EXPECT_EQ(run({"--server", "127.0.0.1:1", "jobs", "list"}).exit_code, 5);

  // --db before or after: the same embedded store.
  const std::string db = s_scratch->file("flags.db");
  ASSERT_EQ(run({"--db", db, "materials", "put", "soft", "--spec", "neo-hookean:mu=0.2"}).exit_code, 0);
  const ProcessResult shown = run({"materials", "show", "soft", "--db", db, "--json"});
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_EQ(json_field(shown.out, "spec"), "\"neo-hookean:mu=0.2\"");
  EXPECT_EQ(run({"materials", "show", "soft"}).exit_code, 4);  // the default store has no 'soft'

  // --help before or after the command: the command's help.
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--help", "design"},
                                               std::vector<std::string>{"design", "-h"},
                                               std::vector<std::string>{"--help", "submit", "design"}}) {
    const ProcessResult help = run(args);
    EXPECT_EQ(help.exit_code, 0);
    EXPECT_NE(help.out.find("TARGET_MESH"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("--detach"), std::string::npos) << help.out;
  }
  const ProcessResult jobs_help = run({"jobs", "--help"});
  EXPECT_NE(jobs_help.out.find("jobs watch"), std::string::npos);

  // Errors name the flag: one line, exit 2.
  const ProcessResult missing = run({"jobs", "list", "--server"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("--server"), std::string::npos) << missing.err;
  const ProcessResult twice = run({"--server", server(), "jobs", "list", "--server", server()});
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("more than once"), std::string::npos) << twice.err;
}

TEST_F(RemoteJobs, SubmitDesignReturnsQueuedThenWatchAndResultWriteWhatDesignWrites) {
  const std::vector<std::string> design_args = {s_scratch->file("bumpy.obj"), "--material", "silicone", "--resolution",
                                                "0", "--max-time", "20"};
  std::vector<std::string> submit = {"--server", server(), "submit", "design"};
  submit.insert(submit.end(), design_args.begin(), design_args.end());
  submit.push_back("--json");
  const ProcessResult submitted = run(submit);
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err;
  const auto lines = split_lines(submitted.out);
  ASSERT_EQ(lines.size(), 1u) << submitted.out;
  // The reply is the stored job, before any worker finished it.
  const std::string state = json_field(lines[0], "state").value_or("");
  EXPECT_TRUE(state == "\"JOB_STATE_QUEUED\"" || state == "\"JOB_STATE_RUNNING\"") << lines[0];
  EXPECT_EQ(json_field(lines[0], "kind"), "\"JOB_KIND_DESIGN\"");
  const std::string job_id = json_field(lines[0], "id").value_or("\"\"");
  const std::string id = job_id.substr(1, job_id.size() - 2);
  ASSERT_EQ(id.rfind("j-", 0), 0u) << lines[0];

  const ProcessResult listed = run({"jobs", "list", "--server", server()});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_NE(listed.out.find(id), std::string::npos) << listed.out;

  const ProcessResult watched = run({"--server", server(), "jobs", "watch", id});
  ASSERT_TRUE(watched.exit_code == 0 || watched.exit_code == 3) << watched.err;
  EXPECT_NE(watched.err.find("completed"), std::string::npos) << watched.err;
  EXPECT_NE(watched.out.find("iterations"), std::string::npos) << watched.out;  // ends with the design's summary
  EXPECT_NE(watched.out.find("162 vertices"), std::string::npos) << watched.out;

  const std::string from_result = s_scratch->file("from-result"), from_design = s_scratch->file("from-design");
  const ProcessResult result = run({"--server", server(), "jobs", "result", id, "--out-dir", from_result});
  ASSERT_TRUE(result.exit_code == 0 || result.exit_code == 3) << result.err;
  std::vector<std::string> design = {"--server", server(), "design"};
  design.insert(design.end(), design_args.begin(), design_args.end());
  design.insert(design.end(), {"--out-dir", from_design});
  const ProcessResult designed = run(design);
  ASSERT_TRUE(designed.exit_code == 0 || designed.exit_code == 3) << designed.err;

  const std::set<std::string> five = {"rest.obj", "inflated.obj", "mold.stl", "report.json", "convergence.csv"};
  EXPECT_EQ(file_names(from_result), five);
  EXPECT_EQ(file_names(from_design), five);
  // For one job, `jobs result` writes byte for byte what `balloon design` wrote: the server built the mold
  // and one writer (contract::job_result_files) made every file.
  const std::string design_id = job_id_in(designed.err);
  ASSERT_EQ(design_id.rfind("j-", 0), 0u) << designed.err;
  const std::string again = s_scratch->file("from-design-result");
  const ProcessResult rewritten = run({"--server", server(), "jobs", "result", design_id, "--out-dir", again});
  ASSERT_TRUE(rewritten.exit_code == 0 || rewritten.exit_code == 3) << rewritten.err;
  EXPECT_EQ(file_names(again), five);
  for (const std::string& name : five)
    EXPECT_EQ(read_file_bytes(again + "/" + name), read_file_bytes(from_design + "/" + name)) << name;
  const std::string report = read_file_bytes(again + "/report.json");
  EXPECT_GT(std::stod(json_field(report, "avg_error_mm").value_or("-1")), 0.0) << report.substr(0, 400);
  const Result<TriMesh> rest = read_mesh(from_result + "/rest.obj");
  const Result<TriMesh> mold = read_mesh(from_result + "/mold.stl");
  ASSERT_TRUE(rest.ok() && mold.ok());
  EXPECT_EQ(rest->vertex_count(), 162);
  EXPECT_GT(mold->face_count(), rest->face_count());  // the tube adds faces
}

TEST_F(RemoteJobs, EveryKindCanBeSubmittedOrDetached) {
  ASSERT_EQ(run({"mesh", "sphere", "--radius", "10", "--subdivisions", "1", "--out", s_scratch->file("s.obj")}).exit_code, 0);
  const std::string csv = std::string(BALLOON_TEST_DATA_DIR) + "/materials/treloar1944_et.csv";
  const std::vector<std::vector<std::string>> commands = {
      {"--server", server(), "submit", "simulate", s_scratch->file("s.obj"), "--material", "latex", "--volume-ratio", "2"},
      {"--server", server(), "submit", s_scratch->file("s.obj"), "--material", "latex", "--volume-ratio", "2"},
      {"simulate", s_scratch->file("s.obj"), "--material", "latex", "--volume-ratio", "2", "--detach", "--server", server()},
      {"--server", server(), "submit", "fit-material", csv, "--test", "equibiaxial", "--model", "neo-hookean"},
      {"--server", server(), "fit-material", csv, "--test", "equibiaxial", "--model", "neo-hookean", "--detach"},
      {"--server", server(), "design", s_scratch->file("bumpy.obj"), "--material", "silicone", "--resolution", "0",
       "--max-time", "5", "--priority", "-5", "--detach"}};
  for (const auto& args : commands) {
    const ProcessResult submitted = run(args);
    ASSERT_EQ(submitted.exit_code, 0) << args[2] << " " << args[3] << ": " << submitted.err;
    const auto lines = split_lines(submitted.out);
    ASSERT_EQ(lines.size(), 1u) << submitted.out;
    EXPECT_EQ(lines[0].rfind("j-", 0), 0u) << lines[0];
    const v1::Job job = get_job(lines[0]);
    EXPECT_NE(job.state(), v1::JOB_STATE_UNSPECIFIED);
    if (job.kind() == v1::JOB_KIND_DESIGN) {
      EXPECT_EQ(job.priority(), -5);
      cancel(lines[0]);  // nothing to wait for
    }
  }
  // Bad input is refused before anything is queued, named as the command names it.
  const ProcessResult bad = run({"--server", server(), "submit", "design", s_scratch->file("bumpy.obj"), "--material",
                                 "silicone", "--scale", "0"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("scale"), std::string::npos) << bad.err;
  EXPECT_EQ(run({"--server", server(), "design", s_scratch->file("bumpy.obj"), "--material", "silicone", "--detach",
                 "--cancel-on-interrupt"})
                .exit_code,
            2);
}

TEST_F(RemoteJobs, CtrlCLeavesTheRemoteDesignRunningAndPrintsHowToResume) {
  auto cli = start_balloon(*s_scratch, {"--server", server(), "design", s_scratch->file("bumpy4.obj"), "--material",
                                        "silicone", "--resolution", "0", "--max-time", "60", "--out-dir",
                                        s_scratch->file("interrupted")});
  // A progress line: the job runs on the server and the CLI follows it.
  ASSERT_TRUE(cli->wait_for_stderr(" s] ", 60.0)) << cli->so_far().err;
  cli->send_signal(SIGINT);
  const ProcessResult ended = cli->wait();
  EXPECT_EQ(ended.exit_code, 130) << ended.err;
  const std::string id = job_id_in(ended.err);
  ASSERT_FALSE(id.empty()) << ended.err;
  EXPECT_NE(ended.err.find("balloon --server " + server() + " jobs watch " + id), std::string::npos) << ended.err;
  EXPECT_EQ(get_job(id).state(), v1::JOB_STATE_RUNNING);

  // Re-attached, the watch sees the same job's progress; Ctrl-C with --cancel-on-interrupt cancels it.
  auto watch = start_balloon(*s_scratch, {"jobs", "watch", id, "--server", server(), "--cancel-on-interrupt"});
  ASSERT_TRUE(watch->wait_for_stderr(id + " [", 60.0)) << watch->so_far().err;
  watch->send_signal(SIGINT);
  const ProcessResult cancelled = watch->wait();
  EXPECT_EQ(cancelled.exit_code, 130) << cancelled.err;
  EXPECT_NE(cancelled.err.find("cancelled"), std::string::npos) << cancelled.err;
  EXPECT_EQ(get_job(id).state(), v1::JOB_STATE_CANCELLED);
}

TEST_F(RemoteJobs, ASecondCtrlCCancels) {
  auto cli = start_balloon(*s_scratch, {"--server", server(), "design", s_scratch->file("bumpy4.obj"), "--material",
                                        "silicone", "--resolution", "0", "--max-time", "60", "--out-dir",
                                        s_scratch->file("twice")});
  ASSERT_TRUE(cli->wait_for_stderr(" s] ", 60.0)) << cli->so_far().err;
  cli->send_signal(SIGINT);
  // The detach message invites a second Ctrl-C within a second.
  ASSERT_TRUE(cli->wait_for_stderr("Ctrl-C again", 10.0)) << cli->so_far().err;
  cli->send_signal(SIGINT);
  const ProcessResult ended = cli->wait();
  EXPECT_EQ(ended.exit_code, 130) << ended.err;
  const std::string id = job_id_in(ended.err);
  ASSERT_FALSE(id.empty()) << ended.err;
  EXPECT_EQ(get_job(id).state(), v1::JOB_STATE_CANCELLED) << ended.err;
}

TEST_F(RemoteJobs, CtrlCOnTheEmbeddedServerLeavesTheJobInTheStoreAndJobsWatchRunsIt) {
  const std::string db = s_scratch->file("embedded.db");
  auto cli = start_embedded_design(db, "embedded-out");
  ASSERT_TRUE(cli->wait_for_stderr(" s] ", 60.0)) << cli->so_far().err;
  cli->send_signal(SIGINT);
  const ProcessResult ended = cli->wait();
  EXPECT_EQ(ended.exit_code, 130) << ended.err;
  const std::string id = job_id_in(ended.err);
  ASSERT_FALSE(id.empty()) << ended.err;
  EXPECT_NE(ended.err.find("balloon --db " + db + " jobs watch " + id), std::string::npos) << ended.err;
  const ProcessResult shown = run({"jobs", "show", id, "--db", db, "--json"});
  EXPECT_EQ(json_field(shown.out, "state"), "\"JOB_STATE_QUEUED\"") << shown.out;

  // `jobs watch` starts the embedded server, which recovers the job and runs it again: its progress
  // shows, and its second attempt is recorded (then cancelled here, to keep the test short).
  auto resumed = start_balloon(*s_scratch, {"--db", db, "jobs", "watch", id, "--cancel-on-interrupt"});
  ASSERT_TRUE(resumed->wait_for_stderr(id + " [", 60.0)) << resumed->so_far().err;
  resumed->send_signal(SIGINT);
  const ProcessResult stopped = resumed->wait();
  EXPECT_EQ(stopped.exit_code, 130) << stopped.err;
  const ProcessResult after = run({"jobs", "show", id, "--db", db, "--json"});
  EXPECT_EQ(json_field(after.out, "state"), "\"JOB_STATE_CANCELLED\"") << after.out;
  EXPECT_EQ(json_number_field(after.out, "attempts"), 2.0) << after.out;
}

TEST_F(RemoteJobs, AJobAKilledCommandLeftInTheEmbeddedStoreDoesNotHoldUpTheNextCommand) {
  const std::string db = s_scratch->file("killed.db");
  auto killed = start_embedded_design(db, "killed-out");
  ASSERT_TRUE(killed->wait_for_stderr(" s] ", 60.0)) << killed->so_far().err;
  const std::string id = job_id_in(killed->so_far().err);
  ASSERT_FALSE(id.empty()) << killed->so_far().err;
  killed->send_signal(SIGKILL);  // no chance to put its job back: the store still says running
  killed->wait();

  // The next command runs its own job and not the design (two such designs took both workers, and the
  // command's job waited behind them); the design is put back in the queue, not left "running" with
  // nothing running it, for `jobs watch` to run.
  const std::string sphere = s_scratch->file("killed-sphere.obj");
  ASSERT_EQ(run({"mesh", "sphere", "--radius", "10", "--subdivisions", "1", "--out", sphere}).exit_code, 0);
  const ProcessResult simulated = run({"simulate", sphere, "--material", "latex", "--volume-ratio", "2", "--db", db});
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  const ProcessResult shown = run({"jobs", "show", id, "--db", db, "--json"});
  EXPECT_EQ(json_field(shown.out, "state"), "\"JOB_STATE_QUEUED\"") << shown.out;
  EXPECT_EQ(json_number_field(shown.out, "attempts"), 1.0) << shown.out;
}

// Issue 12's must-show: a design on a server killed with kill -9 continues, after the restart, from its
// stored checkpoint (the iteration count keeps rising from where it was), finishes, and `jobs result`
// writes the five files.
TEST(RemoteJobsResume, AKilledServerResumesTheDesignFromItsCheckpoint) {
  ScratchDir scratch;
  write_bumpy(scratch.file("bumpy4.obj"), 4);
  const std::string db = scratch.file("server.db");
  auto server = std::make_unique<ServerProcess>(db, std::vector<std::string>{"--workers", "1"});
  const ProcessResult submitted =
      run_balloon(scratch, {"--server", server->address(), "submit", "design", scratch.file("bumpy4.obj"), "--material",
                            "silicone", "--resolution", "0", "--max-time", "25"});
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err;
  const std::string id = job_id_in(submitted.out);
  ASSERT_FALSE(id.empty()) << submitted.out;

  const auto iteration_now = [&](ServerProcess& on) {
    grpc::ClientContext context;
    v1::GetJobRequest request;
    request.set_job_id(id);
    v1::Job job;
    return on.stub()->GetJob(&context, request, &job).ok() && job.last_progress().phase() == "design"
               ? job.last_progress().iteration()
               : 0;
  };
  // Some design iterations, and a second more so that the checkpoint (one a second) holds one of them.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (iteration_now(*server) < 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  const int before_kill = iteration_now(*server);
  ASSERT_GE(before_kill, 3) << "the design never got going";
  EXPECT_EQ(server->stop(SIGKILL), 128 + SIGKILL);

  server = std::make_unique<ServerProcess>(db, std::vector<std::string>{"--workers", "1"});
  const ProcessResult watched = run_balloon(scratch, {"--server", server->address(), "jobs", "watch", id});
  ASSERT_TRUE(watched.exit_code == 0 || watched.exit_code == 3) << watched.err;
  const std::string out_dir = scratch.file("resumed");
  const ProcessResult result = run_balloon(scratch, {"--server", server->address(), "jobs", "result", id, "--out-dir", out_dir});
  ASSERT_TRUE(result.exit_code == 0 || result.exit_code == 3) << result.err;
  EXPECT_EQ(file_names(out_dir), (std::set<std::string>{"rest.obj", "inflated.obj", "mold.stl", "report.json",
                                                       "convergence.csv"}));
  std::ifstream report_file(out_dir + "/report.json");
  const std::string report{std::istreambuf_iterator<char>(report_file), std::istreambuf_iterator<char>()};
  const std::optional<std::string> resumed = json_field(report, "resumed_from_iteration");
  ASSERT_TRUE(resumed.has_value()) << "the design started over instead of resuming: " << report.substr(0, 400);
  const int resumed_from = std::stoi(*resumed);
  EXPECT_GE(resumed_from, 1);
  EXPECT_LE(resumed_from, before_kill);
  const int iterations = std::stoi(json_field(report, "iterations").value_or("0"));
  EXPECT_GT(iterations, resumed_from) << "the count must keep rising from the checkpoint";
  EXPECT_EQ(get_attempts(*server, id), 2);
}

}  // namespace
}  // namespace balloon::testing

namespace balloon::testing {
namespace {

// The curve on a remote server: `simulate --server` writes curve.csv and curve.svg, and `jobs result
// --out-dir` gives the same bytes (proto/contract makes both from the job's CurveReport).
TEST_F(RemoteJobs, ACurveOnTheServerWritesTheSameFilesAsJobsResult) {
  const std::filesystem::path folder = s_scratch->path() / "curve";
  std::filesystem::create_directories(folder);
  const ProcessResult ran = run({"--server", server(), "simulate", s_scratch->file("bumpy.obj"), "--material",
                                 "silicone", "--volume-ratio-range", "1.2:6", "--points", "5", "--out",
                                 folder.string()});
  ASSERT_EQ(ran.exit_code, 0) << ran.err << ran.out;
  const std::string csv = read_file_bytes((folder / "curve.csv").string());
  EXPECT_EQ(csv.rfind("volume_ratio,pressure_kpa,mean_stretch,max_stretch,unstable_modes,converged\n", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6) << csv;

  const ProcessResult listed = run({"--server", server(), "jobs", "list", "--json"});
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  const std::size_t kind = listed.out.find("JOB_KIND_CURVE");
  ASSERT_NE(kind, std::string::npos) << listed.out;
  const std::string job_id = job_id_in(listed.out.substr(listed.out.rfind("\"j-", kind)));
  ASSERT_FALSE(job_id.empty()) << listed.out;
  const std::string out_dir = (s_scratch->path() / "curve_result").string();
  const ProcessResult result = run({"--server", server(), "jobs", "result", job_id, "--out-dir", out_dir});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(file_names(out_dir),
            (std::set<std::string>{"rest.obj", "inflated.obj", "report.json", "curve.csv", "curve.svg"}));
  EXPECT_EQ(read_file_bytes(out_dir + "/curve.csv"), csv);
  EXPECT_EQ(read_file_bytes(out_dir + "/curve.svg"), read_file_bytes((folder / "curve.svg").string()));
}

}  // namespace
}  // namespace balloon::testing
