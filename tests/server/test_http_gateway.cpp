// The HTTP/JSON gateway (README.md, "HTTP/JSON API"): a real balloon-server with `--http 127.0.0.1:0`, driven with
// cpp-httplib's client as a browser would, and compared with the gRPC API of the same server.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>

#include "balloon/v1/balloon.grpc.pb.h"
#include "http/json_mapping.hpp"
#include "http/origin_policy.hpp"
#include "http/static_files.hpp"
#include "jobs/design_job.hpp"
#include "jobs/fit_job.hpp"
#include "contract/job_result_files.hpp"
#include "service/job_reports.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"
#include "net/network_address.hpp"
#include "scratch_dir.hpp"
#include "server_process.hpp"

// Last: httplib.h pulls in <resolv.h>, whose `_res` macro breaks Eigen's headers if they come after it.
#include <httplib.h>

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;
using Clock = std::chrono::steady_clock;

// A server that answers early (413) and closes must fail the client's write, not kill the test process.
const bool SIGPIPE_IGNORED = (signal(SIGPIPE, SIG_IGN), true);

/// A balloon-server child with `--listen 127.0.0.1:0 --http 127.0.0.1:0` (quiet when `--quiet` is among
/// the arguments), with HTTP clients to it.
class HttpServer : public ServerProcess {
 public:
  HttpServer(const ScratchDir& scratch, std::vector<std::string> extra_args)
      : ServerProcess(scratch.file("jobs.db"), with_http(extra_args), /*quiet=*/false) {}

  /// A fresh HTTP client (a browser tab).
  std::unique_ptr<httplib::Client> client() const {
    auto client = std::make_unique<httplib::Client>("127.0.0.1", http_port());
    client->set_read_timeout(30, 0);
    return client;
  }

 private:
  static std::vector<std::string> with_http(std::vector<std::string> args) {
    args.insert(args.begin(), {"--http", "127.0.0.1:0"});
    return args;
  }
};

/// Runs balloon-server with `args` to its exit; returns the exit code and fills `output` (stdout + stderr).
int run_server(const std::vector<std::string>& args, std::string* output) {
  std::string command = BALLOON_SERVER_PATH;
  for (const std::string& arg : args) command += " '" + arg + "'";
  command += " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[512];
  while (const size_t n = fread(buffer, 1, sizeof(buffer), pipe)) output->append(buffer, n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string base64(const std::string& bytes) {
  static constexpr char TABLE[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned n = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int shift : {18, 12, 6, 0}) out += TABLE[(n >> shift) & 63];
  }
  if (i < bytes.size()) {
    unsigned n = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += TABLE[(n >> 18) & 63];
    out += TABLE[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? TABLE[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string sphere_obj(int subdivisions, double radius_mm = 10.0) {
  return write_mesh_to_memory(make_icosphere(radius_mm, subdivisions), "obj");
}

/// A SubmitJobRequest body for a simulate job, built as the page builds it (JSON by hand).
std::string simulate_body(const std::string& obj, const std::string& control,
                          const std::string& material = R"("name":"latex")") {
  return R"({"spec":{"simulate":{"rest_mesh":{"data":")" + base64(obj) + R"(","format":"MESH_FORMAT_OBJ"},"material":{)" +
         material + R"(},"thickness_mm":0.5,)" + control + "}}}";
}

/// A job that keeps the only worker busy for well over a minute until cancelled (cancellation takes one
/// solver iteration, ~0.1 s): a design of the bunny remeshed to 4000 vertices with a 60 s budget.
std::string busy_job_body() {
  std::ifstream in(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/stanford_bunny_1839.obj", std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return R"({"spec":{"design":{"target_mesh":{"data":")" + base64(bytes.str()) +
         R"(","format":"MESH_FORMAT_OBJ"},"material":{"name":"latex"},"resolution":4000,"max_time_s":60}}})";
}

template <class Message>
Message parse(const std::string& json) {
  Message message;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &message);
  EXPECT_TRUE(status.ok()) << status.ToString() << " in " << json.substr(0, 300);
  return message;
}

/// The API's error body {"error":{"code","message"}} as (code, message).
std::pair<std::string, std::string> error_of(const httplib::Result& response) {
  if (!response) return {"<no response>", ""};
  const auto body = parse<google::protobuf::Struct>(response->body);
  const auto& error = body.fields().at("error").struct_value().fields();
  return {error.at("code").string_value(), error.at("message").string_value()};
}

const httplib::Headers JSON_ACCEPT = {{"Accept", "application/json"}};

std::string submit(httplib::Client& client, const std::string& body, const httplib::Headers& headers = {}) {
  const auto response = client.Post("/api/v1/jobs", headers, body, "application/json");
  EXPECT_TRUE(response && response->status == 200) << (response ? response->body : "no response");
  if (!response || response->status != 200) return "";
  return parse<v1::SubmitJobResponse>(response->body).job().id();
}

struct SseEvent {
  std::string type;
  std::string data;
};

/// The events of a whole stream body ("event: T\ndata: D\n\n" blocks; comments skipped).
std::vector<SseEvent> parse_sse(const std::string& body) {
  std::vector<SseEvent> events;
  std::istringstream lines(body);
  std::string line;
  SseEvent current;
  while (std::getline(lines, line)) {
    if (line.empty()) {
      if (!current.type.empty() || !current.data.empty()) events.push_back(current);
      current = SseEvent();
    } else if (line.rfind("event: ", 0) == 0) {
      current.type = line.substr(7);
    } else if (line.rfind("data: ", 0) == 0) {
      current.data += line.substr(6);
    }
  }
  return events;
}

/// GET .../events to the end; returns the events. `status` gets the HTTP status.
std::vector<SseEvent> watch(httplib::Client& client, const std::string& job_id, int* status,
                            const httplib::Headers& headers = {}) {
  std::string body;
  const auto response = client.Get("/api/v1/jobs/" + job_id + "/events", headers,
                                   [&](const char* data, size_t length) {
                                     body.append(data, length);
                                     return true;
                                   });
  *status = response ? response->status : -1;
  if (response && response->status != 200) return {};
  return parse_sse(body);
}

// --- pieces without a server ----------------------------------------------------------------------

TEST(HttpGateway, StatusCodesMapAsTheContractSays) {
  using grpc::StatusCode;
  const std::vector<std::pair<StatusCode, int>> table = {
      {StatusCode::OK, 200},          {StatusCode::INVALID_ARGUMENT, 400},   {StatusCode::UNAUTHENTICATED, 401},
      {StatusCode::PERMISSION_DENIED, 403}, {StatusCode::NOT_FOUND, 404},    {StatusCode::FAILED_PRECONDITION, 409},
      {StatusCode::RESOURCE_EXHAUSTED, 413}, {StatusCode::CANCELLED, 499},   {StatusCode::UNIMPLEMENTED, 501},
      {StatusCode::UNAVAILABLE, 503}, {StatusCode::INTERNAL, 500},           {StatusCode::DEADLINE_EXCEEDED, 500},
      {StatusCode::ALREADY_EXISTS, 500}};
  for (const auto& [code, http] : table) EXPECT_EQ(http::http_status_for(code), http) << http::status_code_name(code);
  EXPECT_EQ(http::error_body(StatusCode::NOT_FOUND, "no job \"x\""),
            R"({"error":{"code":"NOT_FOUND","message":"no job \"x\""}})");
}

TEST(HttpGateway, StaticLookupRefusesTraversalAndFindsIndexFiles) {
  ScratchDir scratch;
  const std::string root = scratch.file("www");
  std::filesystem::create_directories(root + "/sub");
  std::ofstream(root + "/index.html") << "<html>";
  std::ofstream(root + "/sub/index.html") << "<html>sub";
  EXPECT_EQ(http::find_static_file(root, "/").file, root + "/index.html");
  EXPECT_EQ(http::find_static_file(root, "/sub/").file, root + "/sub/index.html");
  EXPECT_EQ(http::find_static_file(root, "/sub").file, root + "/sub/index.html");
  EXPECT_EQ(http::find_static_file(root, "/nope.js").http_status, 404);
  for (const char* bad : {"/../jobs.db", "/sub/../../x", "/..", "/a\\..\\b", "relative"})
    EXPECT_EQ(http::find_static_file(root, bad).http_status, 400) << bad;
  const http::StaticLookup unbuilt = http::find_static_file(scratch.file("missing"), "/");
  EXPECT_EQ(unbuilt.http_status, 404);
  EXPECT_NE(unbuilt.message.find("not built"), std::string::npos) << unbuilt.message;
  EXPECT_EQ(http::content_type_for("a/b.JS"), "text/javascript; charset=utf-8");
  EXPECT_EQ(http::content_type_for("m.stl"), "model/stl");
}

TEST(HttpGateway, LoopbackTestParsesTheAddress) {
  for (const char* host : {"localhost", "LocalHost", "127.0.0.1", "127.255.255.254", "127.0.1.1", "::1",
                           "0:0:0:0:0:0:0:1", "::ffff:127.0.0.1"})
    EXPECT_TRUE(net::is_loopback_host(host)) << host;
  for (const char* host : {"127.evil.example", "127.0.0.1.evil.example", "127.1", "0x7f.0.0.1", "0177.0.0.1",
                           "128.0.0.1", "10.0.0.1", "0.0.0.0", "::", "::2", "localhost.evil.example",
                           "evil.example", "", " 127.0.0.1", "127.0.0.1 "})
    EXPECT_FALSE(net::is_loopback_host(host)) << "'" << host << "'";
  for (const char* address : {"127.0.0.1:50051", "127.0.0.1:0", "[::1]:8080", "localhost:1", "unix:/tmp/balloon.sock"})
    EXPECT_TRUE(net::is_loopback_address(address)) << address;
  for (const char* address : {"127.evil.example:50051", "0.0.0.0:50051", "[::]:50051", "127.0.0.1", ":50051",
                              "127.0.0.1:port", "[::1]", "::1:50051", "192.168.1.10:80"})
    EXPECT_FALSE(net::is_loopback_address(address)) << address;
}

TEST(HttpGateway, OriginPolicyServesLoopbackAndAllowedOriginsOnly) {
  const Result<http::WebOrigin> allowed = http::parse_origin("HTTPS://Balloon.Example/");
  ASSERT_TRUE(allowed.ok()) << allowed.error();
  EXPECT_EQ(allowed->scheme, "https");
  EXPECT_EQ(allowed->host, "balloon.example");
  EXPECT_EQ(allowed->port, 443);
  for (const char* bad : {"balloon.example", "ftp://balloon.example", "https://balloon.example/app",
                          "https://user@balloon.example", "https://balloon.example:99999", "https://", "null",
                          "https://[::1", "https://a b"})
    EXPECT_FALSE(http::parse_origin(bad).ok()) << bad;

  const http::OriginPolicy policy(/*tls=*/false, 8080, {*allowed});
  const auto refused = [&](const char* host, const char* origin) {
    const std::string host_text = host == nullptr ? "" : host, origin_text = origin == nullptr ? "" : origin;
    return !policy.refusal(host == nullptr ? nullptr : &host_text, origin == nullptr ? nullptr : &origin_text).empty();
  };
  // Scripts and curl: no Origin, a loopback Host with this port.
  for (const char* host : {"127.0.0.1:8080", "localhost:8080", "[::1]:8080", "127.0.0.2:8080", "balloon.example"})
    EXPECT_FALSE(refused(host, nullptr)) << host;
  // DNS rebinding and look-alikes.
  for (const char* host : {"evil.example:8080", "evil.example", "127.evil.example:8080", "127.0.0.1:8081",
                           "127.0.0.1", "localhost", "127.0.0.1:8080:1", "[::1", ""})
    EXPECT_TRUE(refused(host, nullptr)) << host;
  EXPECT_TRUE(refused(nullptr, nullptr)) << "no Host header";
  // The page itself, on any loopback name, and the allowed origin.
  for (const char* origin : {"http://127.0.0.1:8080", "http://localhost:8080", "http://[::1]:8080", "https://balloon.example",
                             "https://balloon.example:443"})
    EXPECT_FALSE(refused("127.0.0.1:8080", origin)) << origin;
  for (const char* origin : {"http://evil.example", "https://127.0.0.1:8080", "http://127.0.0.1:3000", "null",
                             "http://balloon.example", "https://balloon.example:8443", "http://127.evil.example:8080", ""})
    EXPECT_TRUE(refused("127.0.0.1:8080", origin)) << origin;
}

// --- a real server ----------------------------------------------------------------------------------

TEST(HttpGateway, MaterialsAreListedReadWrittenAndDeletedAsJson) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  EXPECT_NE(server.output().find("(web root "), std::string::npos) << server.output();
  auto client = server.client();
  auto health = client->Get("/api/v1/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->body, R"({"status":"ok"})");

  auto listed = client->Get("/api/v1/materials", JSON_ACCEPT);
  ASSERT_TRUE(listed);
  EXPECT_EQ(listed->status, 200);
  EXPECT_EQ(listed->get_header_value("Content-Type"), "application/json");
  // Proto field names, int64 as strings, every primitive printed.
  EXPECT_NE(listed->body.find(R"("created_ms":"0")"), std::string::npos) << listed->body.substr(0, 300);
  const auto materials = parse<v1::ListMaterialsResponse>(listed->body);
  ASSERT_GE(materials.materials_size(), 2);
  EXPECT_EQ(materials.materials(0).name(), "silicone");
  EXPECT_TRUE(materials.materials(0).preset());

  auto put = client->Put("/api/v1/materials/soft", R"({"spec":"neo-hookean:mu=0.25","description":"test"})",
                         "application/json");
  ASSERT_TRUE(put);
  ASSERT_EQ(put->status, 200) << put->body;
  EXPECT_EQ(parse<v1::Material>(put->body).model(), "neo-hookean");
  auto got = client->Get("/api/v1/materials/soft");
  ASSERT_TRUE(got);
  EXPECT_DOUBLE_EQ(parse<v1::Material>(got->body).params().at("mu"), 0.25);
  auto renamed = client->Put("/api/v1/materials/soft", R"({"name":"other","spec":"neo-hookean:mu=0.25"})",
                             "application/json");
  ASSERT_TRUE(renamed);
  EXPECT_EQ(renamed->status, 400);
  EXPECT_EQ(error_of(renamed).first, "INVALID_ARGUMENT");
  auto preset = client->Delete("/api/v1/materials/latex");
  ASSERT_TRUE(preset);
  EXPECT_EQ(preset->status, 403);
  EXPECT_EQ(error_of(preset).first, "PERMISSION_DENIED");
  auto deleted = client->Delete("/api/v1/materials/soft");
  ASSERT_TRUE(deleted);
  EXPECT_EQ(deleted->status, 200);
  EXPECT_EQ(deleted->body, "{}");
  auto gone = client->Get("/api/v1/materials/soft");
  ASSERT_TRUE(gone);
  EXPECT_EQ(gone->status, 404);
}

TEST(HttpGateway, SimulateJobStreamsProgressAndServesItsMeshes) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  auto client = server.client();
  const TriMesh sphere = make_icosphere(10.0, 3);  // 642 vertices
  // The only worker is busy until the stream is open, so the stream sees the job from its start.
  const std::string busy = submit(*client, busy_job_body());
  // Pressure control walks the volume path in steps: several progress events with shapes.
  const std::string job_id = submit(*client, simulate_body(write_mesh_to_memory(sphere, "obj"), R"("pressure_kpa":18)",
                                                           R"("spec":"neo-hookean:mu=0.3")"));
  ASSERT_FALSE(busy.empty());
  ASSERT_FALSE(job_id.empty());

  std::string body;
  std::atomic<bool> opened{false};
  int status = 0;
  std::thread watcher([&] {
    auto tab = server.client();
    const auto response = tab->Get("/api/v1/jobs/" + job_id + "/events", [&](const char* data, size_t length) {
      body.append(data, length);
      opened = true;
      return true;
    });
    status = response ? response->status : -1;
  });
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (!opened && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  auto cancelled = client->Post("/api/v1/jobs/" + busy + "/cancel", "", "application/json");
  ASSERT_TRUE(cancelled);
  EXPECT_EQ(cancelled->status, 200);
  watcher.join();
  ASSERT_EQ(status, 200);
  const std::vector<SseEvent> events = parse_sse(body);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(parse<v1::JobEvent>(events.front().data).state(), v1::JOB_STATE_QUEUED);
  ASSERT_GE(events.size(), 3u);
  int progress_events = 0, mesh_events = 0;
  for (size_t i = 0; i + 1 < events.size(); ++i) {
    ASSERT_EQ(events[i].type, "job") << i;
    const auto event = parse<v1::JobEvent>(events[i].data);
    EXPECT_EQ(event.job_id(), job_id);
    if (event.has_progress()) ++progress_events;
    if (event.has_mesh()) {
      // Connectivity comes once, in the first mesh event; positions every time, as JSON numbers.
      EXPECT_EQ(event.mesh().triangles_size() > 0, mesh_events == 0) << "mesh event " << mesh_events;
      EXPECT_EQ(event.mesh().positions_mm_size(), 3 * sphere.vertex_count());
      ++mesh_events;
    }
  }
  EXPECT_GE(progress_events, 2) << body.substr(0, 3000);
  EXPECT_GE(mesh_events, 1);
  EXPECT_EQ(parse<v1::JobEvent>(events[events.size() - 2].data).state(), v1::JOB_STATE_COMPLETED);
  EXPECT_EQ(events.back().type, "end");
  EXPECT_EQ(events.back().data, R"({"code":"OK","message":""})");

  auto result = client->Get("/api/v1/jobs/" + job_id + "/result?format=MESH_FORMAT_OBJ");
  ASSERT_TRUE(result);
  ASSERT_EQ(result->status, 200);
  const auto job_result = parse<v1::JobResult>(result->body);  // bytes came as base64
  EXPECT_EQ(job_result.kind(), v1::JOB_KIND_SIMULATE);
  EXPECT_TRUE(job_result.converged());
  ASSERT_TRUE(job_result.has_simulate_report());
  EXPECT_GT(job_result.simulate_report().pressure_kpa(), 0.0);
  EXPECT_FALSE(job_result.has_mold_mesh()) << "only a design has a mold";

  for (const char* name : {"rest.obj", "inflated.obj"}) {
    auto file = client->Get("/api/v1/jobs/" + job_id + "/files/" + name);
    ASSERT_TRUE(file);
    ASSERT_EQ(file->status, 200) << name << ": " << file->body;
    EXPECT_EQ(file->get_header_value("Content-Disposition"), std::string("attachment; filename=\"") + name + "\"");
    const Result<TriMesh> mesh = read_mesh_from_memory(file->body, "obj");
    ASSERT_TRUE(mesh.ok()) << name << ": " << mesh.error();
    EXPECT_EQ(mesh->vertex_count(), sphere.vertex_count()) << name;
    EXPECT_EQ(file->body, std::string(name) == "rest.obj" ? job_result.rest_mesh().data() : job_result.inflated_mesh().data());
  }
  auto report = client->Get("/api/v1/jobs/" + job_id + "/files/report.json");
  ASSERT_TRUE(report);
  EXPECT_EQ(report->body, contract::result_report_json(job_result));
  for (const char* name : {"mold.stl", "convergence.csv", "fit.svg", "secrets.txt"}) {
    auto missing = client->Get("/api/v1/jobs/" + job_id + "/files/" + name);
    ASSERT_TRUE(missing);
    EXPECT_EQ(missing->status, 404) << name;
    EXPECT_EQ(error_of(missing).first, "NOT_FOUND") << name;
  }
  // The job list shows it, filtered by state.
  auto listed = client->Get("/api/v1/jobs?state=JOB_STATE_COMPLETED&page_size=10");
  ASSERT_TRUE(listed);
  ASSERT_EQ(listed->status, 200) << listed->body;
  const auto jobs = parse<v1::ListJobsResponse>(listed->body);
  ASSERT_EQ(jobs.jobs_size(), 1);
  EXPECT_EQ(jobs.jobs(0).id(), job_id);
  auto none = client->Get("/api/v1/jobs?state=JOB_STATE_RUNNING");
  ASSERT_TRUE(none);
  EXPECT_EQ(parse<v1::ListJobsResponse>(none->body).jobs_size(), 0);
}

TEST(HttpGateway, DesignJobServesTheMoldTheServerBuilt) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  auto client = server.client();
  const std::string body = R"({"spec":{"design":{"target_mesh":{"data":")" + base64(sphere_obj(2)) +
                           R"(","format":"MESH_FORMAT_OBJ"},"material":{"name":"latex"},"resolution":0,)"
                           R"("max_time_s":5}}})";
  const std::string job_id = submit(*client, body);
  ASSERT_FALSE(job_id.empty());
  int status = 0;
  const std::vector<SseEvent> events = watch(*client, job_id, &status);
  ASSERT_EQ(status, 200);
  ASSERT_GE(events.size(), 2u);
  EXPECT_EQ(events.back().data, R"({"code":"OK","message":""})");
  bool errors_reported = false;
  for (const SseEvent& event : events)
    if (event.type == "job" && parse<v1::JobEvent>(event.data).progress().avg_error_mm() >= 0.0 &&
        parse<v1::JobEvent>(event.data).has_progress())
      errors_reported = true;
  EXPECT_TRUE(errors_reported) << "design progress carries the error for the page's plot";

  auto rest = client->Get("/api/v1/jobs/" + job_id + "/files/rest.obj");
  auto report = client->Get("/api/v1/jobs/" + job_id + "/files/report.json");
  auto mold = client->Get("/api/v1/jobs/" + job_id + "/files/mold.stl");
  ASSERT_TRUE(rest && report && mold);
  ASSERT_EQ(mold->status, 200) << mold->body;
  EXPECT_EQ(mold->get_header_value("Content-Type"), "model/stl");
  const Result<TriMesh> rest_mesh = read_mesh_from_memory(rest->body, "obj");
  ASSERT_TRUE(rest_mesh.ok()) << rest_mesh.error();
  const Result<TriMesh> mold_mesh = read_mesh_from_memory(mold->body, "stl");
  ASSERT_TRUE(mold_mesh.ok()) << mold_mesh.error();
  EXPECT_GT(mold_mesh->face_count(), rest_mesh->face_count());  // the rest shape plus a tube
  // Byte for byte the mold GetResult returns (what the CLI writes), and the report of the same result.
  auto result = client->Get("/api/v1/jobs/" + job_id + "/result");
  ASSERT_TRUE(result);
  ASSERT_EQ(result->status, 200) << result->body;
  const auto job_result = parse<v1::JobResult>(result->body);
  EXPECT_EQ(job_result.mold_mesh().format(), v1::MESH_FORMAT_STL);
  EXPECT_EQ(mold->body, job_result.mold_mesh().data());
  EXPECT_EQ(report->body, contract::result_report_json(job_result));
  ASSERT_TRUE(job_result.design_report().has_mold());
  EXPECT_GT(job_result.design_report().mold().tube_radius_mm(), 0.0);
  auto convergence = client->Get("/api/v1/jobs/" + job_id + "/files/convergence.csv");
  ASSERT_TRUE(convergence);
  ASSERT_EQ(convergence->status, 200) << convergence->body;
  EXPECT_EQ(convergence->body.rfind("time_s,iteration,avg_error_mm,max_error_mm,residual_norm\n", 0), 0u);
  EXPECT_EQ(convergence->body, contract::convergence_csv(job_result.design_report().convergence()));
}

TEST(HttpGateway, FitJobServesTheSamePlotAsTheCli) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  auto client = server.client();
  std::ifstream in(std::string(BALLOON_TEST_DATA_DIR) + "/materials/treloar1944_et.csv", std::ios::binary);
  std::ostringstream csv;
  csv << in.rdbuf();
  const std::string body = R"({"spec":{"fit_material":{"data":[{"csv":")" + base64(csv.str()) +
                           R"(","test":"equibiaxial","label":"sheet-a.csv"}],"model":"hart-smith"}}})";
  const std::string job_id = submit(*client, body);
  ASSERT_FALSE(job_id.empty());
  int status = 0;
  const std::vector<SseEvent> events = watch(*client, job_id, &status);
  ASSERT_EQ(status, 200);
  ASSERT_FALSE(events.empty());
  ASSERT_EQ(events.back().data, R"({"code":"OK","message":""})");

  auto plot = client->Get("/api/v1/jobs/" + job_id + "/files/fit.svg");
  auto report = client->Get("/api/v1/jobs/" + job_id + "/files/report.json");
  ASSERT_TRUE(plot && report);
  ASSERT_EQ(plot->status, 200) << plot->body;
  EXPECT_EQ(plot->get_header_value("Content-Type"), "image/svg+xml");
  EXPECT_EQ(plot->body.rfind("<svg", 0), 0u);
  // What `balloon fit-material --plot` draws from the same report, with the label the request gave.
  std::vector<jobs::FitDataFile> files(1);
  files[0].label = "sheet-a.csv";
  files[0].csv_text = csv.str();
  files[0].test = "equibiaxial";
  const Result<jobs::FitInput> input = jobs::prepare_fit(files, "hart-smith");
  ASSERT_TRUE(input.ok()) << input.error();
  auto result = client->Get("/api/v1/jobs/" + job_id + "/result");
  ASSERT_TRUE(result);
  const auto job_result = parse<v1::JobResult>(result->body);
  EXPECT_EQ(report->body, contract::result_report_json(job_result));
  const Result<jobs::FitOutcome> outcome = service::fit_outcome_from_report(*input, job_result.fit_report());
  ASSERT_TRUE(outcome.ok()) << outcome.error();
  EXPECT_EQ(plot->body, jobs::fit_plot_svg(*input, *outcome));
  for (const char* name : {"rest.obj", "mold.stl"}) {
    auto missing = client->Get("/api/v1/jobs/" + job_id + "/files/" + name);
    ASSERT_TRUE(missing);
    EXPECT_EQ(missing->status, 404) << name;
  }
}

TEST(HttpGateway, ErrorsCarryTheServiceCodeAndMessage) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1", "--max-message-mb", "1"});
  auto client = server.client();
  auto stub = server.stub();

  auto bad_json = client->Post("/api/v1/jobs", "{\"spec\": {", "application/json");
  ASSERT_TRUE(bad_json);
  EXPECT_EQ(bad_json->status, 400);
  EXPECT_EQ(error_of(bad_json).first, "INVALID_ARGUMENT");
  EXPECT_NE(error_of(bad_json).second.find("not valid JSON"), std::string::npos) << error_of(bad_json).second;
  auto typo = client->Post("/api/v1/jobs", R"({"spec":{"simulate":{"thickness":1}}})", "application/json");
  ASSERT_TRUE(typo);
  EXPECT_EQ(typo->status, 400);
  EXPECT_NE(error_of(typo).second.find("thickness"), std::string::npos) << error_of(typo).second;

  // A bad mesh: the HTTP answer is the gRPC answer, code and message.
  const std::string garbage = "\x01\x02garbage\xff";
  auto bad_mesh = client->Post("/api/v1/jobs", simulate_body(garbage, R"("volume_ratio":2)"), "application/json");
  ASSERT_TRUE(bad_mesh);
  EXPECT_EQ(bad_mesh->status, 400);
  v1::SubmitJobRequest request;
  request.mutable_spec()->mutable_simulate()->mutable_rest_mesh()->set_data(garbage);
  request.mutable_spec()->mutable_simulate()->mutable_rest_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  request.mutable_spec()->mutable_simulate()->mutable_material()->set_name("latex");
  request.mutable_spec()->mutable_simulate()->set_thickness_mm(0.5);
  request.mutable_spec()->mutable_simulate()->set_volume_ratio(2);
  grpc::ClientContext context;
  v1::SubmitJobResponse reply;
  const grpc::Status direct = stub->SubmitJob(&context, request, &reply);
  ASSERT_EQ(direct.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(error_of(bad_mesh).first, "INVALID_ARGUMENT");
  EXPECT_EQ(error_of(bad_mesh).second, direct.error_message());

  for (const char* path : {"/api/v1/jobs/j-0000000000000000", "/api/v1/jobs/j-0000000000000000/events",
                           "/api/v1/jobs/j-0000000000000000/result", "/api/v1/nothing-here"}) {
    auto missing = client->Get(path);
    ASSERT_TRUE(missing) << path;
    EXPECT_EQ(missing->status, 404) << path;
    EXPECT_EQ(error_of(missing).first, "NOT_FOUND") << path;
  }
  auto bad_state = client->Get("/api/v1/jobs?state=RUNNING");
  ASSERT_TRUE(bad_state);
  EXPECT_EQ(bad_state->status, 400);

  // Larger than --max-message-mb: 413 before the service sees it.
  const std::string huge = simulate_body(std::string(1 << 20, '#'), R"("volume_ratio":2)");
  auto too_big = client->Post("/api/v1/jobs", huge, "application/json");
  ASSERT_TRUE(too_big);
  EXPECT_EQ(too_big->status, 413);
  EXPECT_EQ(error_of(too_big).first, "RESOURCE_EXHAUSTED");

  // An unfinished job: its result is 409 with the service's message; cancelling it works.
  auto long_client = server.client();
  const std::string job_id = submit(*long_client, busy_job_body());
  ASSERT_FALSE(job_id.empty());
  auto early = client->Get("/api/v1/jobs/" + job_id + "/result");
  ASSERT_TRUE(early);
  EXPECT_EQ(early->status, 409);
  EXPECT_EQ(error_of(early).first, "FAILED_PRECONDITION");
  EXPECT_FALSE(error_of(early).second.empty());
  auto early_file = client->Get("/api/v1/jobs/" + job_id + "/files/rest.obj");
  ASSERT_TRUE(early_file);
  EXPECT_EQ(early_file->status, 409);
  auto cancelled = client->Post("/api/v1/jobs/" + job_id + "/cancel", "{}", "application/json");
  ASSERT_TRUE(cancelled);
  ASSERT_EQ(cancelled->status, 200) << cancelled->body;
  EXPECT_EQ(parse<v1::Job>(cancelled->body).state(), v1::JOB_STATE_CANCELLED);
  int status = 0;
  const std::vector<SseEvent> events = watch(*client, job_id, &status);
  ASSERT_EQ(status, 200);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(parse<v1::JobEvent>(events.front().data).state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(events.back().type, "end");
}

TEST(HttpGateway, TokensAreRequiredAsForGrpc) {
  ScratchDir scratch;
  std::ofstream(scratch.file("tokens")) << "alice alice-token-0123456789\nbob bob-token-0123456789ab\n";
  HttpServer server(scratch, {"--workers", "1", "--token-file", scratch.file("tokens")});
  auto client = server.client();
  const httplib::Headers alice = {{"Authorization", "Bearer alice-token-0123456789"}};
  const httplib::Headers bob = {{"Authorization", "Bearer bob-token-0123456789ab"}};

  auto anonymous = client->Get("/api/v1/materials");
  ASSERT_TRUE(anonymous);
  EXPECT_EQ(anonymous->status, 401);
  EXPECT_EQ(error_of(anonymous).first, "UNAUTHENTICATED");
  auto wrong = client->Get("/api/v1/materials", {{"Authorization", "Bearer not-a-token-0123456789"}});
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 401);
  auto garbled = client->Get("/api/v1/materials", {{"Authorization", "Bearer \x7f\x01"}});
  ASSERT_TRUE(garbled);
  EXPECT_EQ(garbled->status, 401);
  auto allowed = client->Get("/api/v1/materials", alice);
  ASSERT_TRUE(allowed);
  EXPECT_EQ(allowed->status, 200);

  const std::string job_id = submit(*client, simulate_body(sphere_obj(2), R"("volume_ratio":2)"), alice);
  ASSERT_FALSE(job_id.empty());
  int status = 0;
  EXPECT_TRUE(watch(*client, job_id, &status).empty());
  EXPECT_EQ(status, 401) << "an event stream without a token is refused before it opens";
  watch(*client, job_id, &status, bob);
  EXPECT_EQ(status, 404) << "another tenant's job does not exist for bob";
  const std::vector<SseEvent> events = watch(*client, job_id, &status, alice);
  EXPECT_EQ(status, 200);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().data, R"({"code":"OK","message":""})");
  auto rest = client->Get("/api/v1/jobs/" + job_id + "/files/rest.obj", bob);
  ASSERT_TRUE(rest);
  EXPECT_EQ(rest->status, 404);
  server.stop(SIGTERM);
  EXPECT_EQ(server.log().find("alice-token"), std::string::npos) << "tokens must never be logged";
}

TEST(HttpGateway, ServesTheWebRootAndNothingOutsideIt) {
  ScratchDir scratch;
  const std::string root = scratch.file("www");
  std::filesystem::create_directories(root + "/samples");
  std::ofstream(root + "/index.html") << "<!doctype html><title>balloon</title>";
  std::ofstream(root + "/app.js") << "console.log('hi');";
  std::ofstream(root + "/samples/ball.obj") << "v 0 0 0\n";
  std::ofstream(scratch.file("secret.txt")) << "top secret";
  HttpServer server(scratch, {"--quiet", "--web-root", root});
  EXPECT_NE(server.output().find("(web root " + root + ")"), std::string::npos) << server.output();
  auto client = server.client();

  auto index = client->Get("/");
  ASSERT_TRUE(index);
  EXPECT_EQ(index->status, 200);
  EXPECT_EQ(index->body, "<!doctype html><title>balloon</title>");
  EXPECT_EQ(index->get_header_value("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(index->get_header_value("Cache-Control"), "no-cache");
  auto script = client->Get("/app.js");
  ASSERT_TRUE(script);
  EXPECT_EQ(script->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  auto sample = client->Get("/samples/ball.obj");
  ASSERT_TRUE(sample);
  EXPECT_EQ(sample->body, "v 0 0 0\n");
  EXPECT_EQ(sample->get_header_value("Content-Type"), "model/obj");
  auto missing = client->Get("/nope.css");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);

  client->set_url_encode(false);  // send the paths exactly as written
  for (const char* path : {"/../secret.txt", "/samples/../../secret.txt", "/%2e%2e/secret.txt", "/..%2fsecret.txt"}) {
    auto escaped = client->Get(path);
    ASSERT_TRUE(escaped) << path;
    EXPECT_NE(escaped->status, 200) << path;
    EXPECT_EQ(escaped->body.find("top secret"), std::string::npos) << path;
  }

  // Without a built page the API still works and / says what to do.
  ScratchDir other;
  HttpServer unbuilt(other, {"--quiet", "--web-root", other.file("no-such-dir")});
  auto page = unbuilt.client()->Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 404);
  EXPECT_NE(page->body.find("not built"), std::string::npos) << page->body;
  auto api = unbuilt.client()->Get("/api/v1/health");
  ASSERT_TRUE(api);
  EXPECT_EQ(api->status, 200);
}

// Each open stream holds one of the gateway's 16 threads. Browsers that drop streams on a quiet (queued)
// job must give them back at once, or a few reloads would starve every other request.
TEST(HttpGateway, AbandonedEventStreamsFreeTheirThreadsAndShutdownEndsStreams) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  auto client = server.client();
  const std::string busy = submit(*client, busy_job_body());
  const std::string queued = submit(*client, simulate_body(sphere_obj(2), R"("volume_ratio":2)"));
  ASSERT_FALSE(busy.empty());
  ASSERT_FALSE(queued.empty());
  // More tabs than threads: without the threads coming back, the 17th would wait for a keepalive (15 s).
  const auto started = Clock::now();
  for (int i = 0; i < 24; ++i) {
    auto tab = server.client();
    bool got_first = false;
    tab->Get("/api/v1/jobs/" + queued + "/events", [&](const char* data, size_t length) {
      got_first = std::string(data, length).find("event: job") != std::string::npos;
      return !got_first;  // false: the client hangs up, like a closed tab
    });
    EXPECT_TRUE(got_first) << i;
  }
  auto health = client->Get("/api/v1/health");
  ASSERT_TRUE(health) << "no worker thread left";
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - started).count(), 5.0);
  auto state = client->Get("/api/v1/jobs/" + queued);
  ASSERT_TRUE(state);
  EXPECT_EQ(parse<v1::Job>(state->body).state(), v1::JOB_STATE_QUEUED) << "the stream test needs a quiet job";

  // SIGTERM while a stream is open: it ends with `event: end` UNAVAILABLE and the server exits cleanly.
  std::string body;
  std::atomic<bool> streaming{false};
  std::thread watcher([&] {
    auto tab = server.client();
    tab->Get("/api/v1/jobs/" + queued + "/events", [&](const char* data, size_t length) {
      body.append(data, length);
      streaming = true;
      return true;
    });
  });
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (!streaming && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto stopping = Clock::now();
  EXPECT_EQ(server.stop(SIGTERM), 0);
  watcher.join();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - stopping).count(), 5.0);
  const std::vector<SseEvent> events = parse_sse(body);
  ASSERT_FALSE(events.empty()) << body;
  EXPECT_EQ(events.back().type, "end");
  EXPECT_EQ(events.back().data, R"({"code":"UNAVAILABLE","message":"the server is shutting down"})");
}

TEST(HttpGateway, FlagsFollowTheLoopbackRuleAndAreDocumented) {
  std::string output;
  EXPECT_EQ(run_server({"--http", "0.0.0.0:0", "--db", ":memory:"}, &output), 2);
  EXPECT_NE(output.find("--token-file"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--help"}, &output), 0);
  EXPECT_NE(output.find("--http HOST:PORT"), std::string::npos) << output;
  EXPECT_NE(output.find("--web-root DIR"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--listen", "127.0.0.1:0", "--db", ":memory:", "--http", "127.0.0.1:http"}, &output), 1);
  EXPECT_NE(output.find("port 'http'"), std::string::npos) << output;
}

// --- what a browser on another site can make it do (README.md, "Security") -------------------------------

/// The number of jobs the caller sees.
int job_count(httplib::Client& client) {
  const auto listed = client.Get("/api/v1/jobs");
  if (!listed || listed->status != 200) return -1;
  return parse<v1::ListJobsResponse>(listed->body).jobs_size();
}

TEST(HttpGateway, CrossSiteRequestsAndDnsRebindingAreRefused) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1"});
  auto client = server.client();
  const std::string own = "127.0.0.1:" + std::to_string(server.http_port());
  const std::string body = simulate_body(sphere_obj(1), R"("volume_ratio":2)");

  // CSRF: a form or fetch with `text/plain` goes cross-site without a preflight. Refused before the service.
  auto multipart = client->Post("/api/v1/jobs", body.substr(0, 4000), "multipart/form-data; boundary=x");
  ASSERT_TRUE(multipart);
  EXPECT_EQ(multipart->status, 400) << "httplib refuses the malformed form itself";
  for (const char* type : {"text/plain", "application/x-www-form-urlencoded", "application/jsonx", "text/json"}) {
    auto posted = client->Post("/api/v1/jobs", body.substr(0, 4000), type);
    ASSERT_TRUE(posted) << type;
    EXPECT_EQ(posted->status, 415) << type;
    EXPECT_EQ(error_of(posted).first, "INVALID_ARGUMENT") << type;
    EXPECT_NE(error_of(posted).second.find("Content-Type: application/json"), std::string::npos) << error_of(posted).second;
  }
  auto untyped = client->Post("/api/v1/jobs", httplib::Headers{}, body, "");
  ASSERT_TRUE(untyped);
  EXPECT_EQ(untyped->status, 415) << "a body without a Content-Type";
  auto put = client->Put("/api/v1/materials/soft", R"({"spec":"neo-hookean:mu=0.25"})", "text/plain");
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 415);

  // A page on another site, even with the right Content-Type (the browser sends its Origin).
  for (const char* origin : {"http://evil.example", "null", "http://localhost:1", "http://127.0.0.1:1"}) {
    auto posted = client->Post("/api/v1/jobs", {{"Origin", origin}}, body, "application/json");
    ASSERT_TRUE(posted) << origin;
    EXPECT_EQ(posted->status, 403) << origin;
    EXPECT_EQ(error_of(posted).first, "PERMISSION_DENIED") << origin;
    EXPECT_NE(error_of(posted).second.find("cross-origin"), std::string::npos) << error_of(posted).second;
  }
  EXPECT_EQ(job_count(*client), 0) << "no refused request may create a job";

  // DNS rebinding: another name pointed at 127.0.0.1 reaches the port, with that name as Host.
  for (const std::string& host : {std::string("evil.example"), "evil.example:" + std::to_string(server.http_port()),
                                 "127.evil.example:" + std::to_string(server.http_port()), std::string("127.0.0.1:1")}) {
    // (/api/v1/health answers any Host: probes call it by address, and it reveals nothing.)
    for (const char* path : {"/api/v1/jobs", "/api/v1/materials", "/"}) {
      auto got = client->Get(path, {{"Host", host}});
      ASSERT_TRUE(got) << host << path;
      EXPECT_EQ(got->status, 403) << host << path;
      EXPECT_EQ(got->body.find("\"jobs\""), std::string::npos) << host << path;
    }
  }

  // The page itself (its own origin, on any loopback name) and scripts without an Origin still work.
  const std::string job = submit(*client, body, {{"Origin", "http://" + own}});
  ASSERT_FALSE(job.empty());
  EXPECT_FALSE(submit(*client, body).empty()) << "curl-like: no Origin";
  EXPECT_FALSE(submit(*client, body, {{"Host", "localhost:" + std::to_string(server.http_port())},
                                      {"Origin", "http://localhost:" + std::to_string(server.http_port())}})
                   .empty());
  auto cancelled = client->Post("/api/v1/jobs/" + job + "/cancel");  // curl -X POST: no body, no type
  ASSERT_TRUE(cancelled);
  EXPECT_EQ(cancelled->status, 200) << cancelled->body;
  auto charset = client->Put("/api/v1/materials/soft", R"({"spec":"neo-hookean:mu=0.25"})",
                             "Application/JSON; charset=utf-8");
  ASSERT_TRUE(charset);
  EXPECT_EQ(charset->status, 200) << charset->body;
  EXPECT_EQ(job_count(*client), 3);
}

TEST(HttpGateway, AllowedOriginFlagAdmitsThatPageOnly) {
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1", "--http-allowed-origin", "https://balloon.example",
                              "--http-allowed-origin", "http://lab.example:8000"});
  auto client = server.client();
  const std::string body = R"({"spec":"neo-hookean:mu=0.25"})";
  // As behind a proxy that forwards the public name: Host is the allowed origin's host.
  for (const auto& [host, origin] : std::vector<std::pair<std::string, std::string>>{
           {"balloon.example", "https://balloon.example"},
           {"lab.example:8000", "http://lab.example:8000"},
           {"127.0.0.1:" + std::to_string(server.http_port()), "https://balloon.example"}}) {
    auto put = client->Put("/api/v1/materials/soft", {{"Host", host}, {"Origin", origin}}, body, "application/json");
    ASSERT_TRUE(put) << origin;
    EXPECT_EQ(put->status, 200) << host << " " << origin << ": " << put->body;
  }
  for (const auto& [host, origin] : std::vector<std::pair<std::string, std::string>>{
           {"balloon.example", "http://balloon.example"},        // another scheme is another origin
           {"balloon.example", "https://balloon.example:8443"},  // and another port
           {"balloon.example", "https://evil.example"},
           {"evil.example", "https://balloon.example"}}) {
    auto put = client->Put("/api/v1/materials/soft", {{"Host", host}, {"Origin", origin}}, body, "application/json");
    ASSERT_TRUE(put) << origin;
    EXPECT_EQ(put->status, 403) << host << " " << origin;
  }
  std::string output;
  EXPECT_EQ(run_server({"--http", "127.0.0.1:0", "--db", ":memory:", "--http-allowed-origin", "balloon.example"}, &output), 2);
  EXPECT_NE(output.find("--http-allowed-origin"), std::string::npos) << output;
  EXPECT_NE(output.find("SCHEME://HOST[:PORT]"), std::string::npos) << output;
}

// An open event stream holds one worker thread; the pool has --http-max-event-streams more threads than it
// needs for the rest, and streams past that number get 503, so /health never waits behind streams.
TEST(HttpGateway, ThirtyTwoOpenEventStreamsLeaveHealthAnswering) {
  constexpr int HELD = 32, CAP = 34;
  ScratchDir scratch;
  HttpServer server(scratch, {"--quiet", "--workers", "1", "--http-max-event-streams", std::to_string(CAP)});
  auto client = server.client();
  const std::string busy = submit(*client, busy_job_body());
  const std::string queued = submit(*client, simulate_body(sphere_obj(1), R"("volume_ratio":2)"));
  ASSERT_FALSE(busy.empty());
  ASSERT_FALSE(queued.empty());
  const std::string path = "/api/v1/jobs/" + queued + "/events";

  struct HeldStream {
    std::atomic<bool> opened{false};
    std::atomic<bool> done{false};  ///< the request returned (a 503, or the stream's end)
    std::string body;
    std::thread reader;
  };
  std::vector<std::unique_ptr<HeldStream>> held;
  const auto hold_one = [&] {
    auto stream = std::make_unique<HeldStream>();
    HeldStream* raw = stream.get();
    raw->reader = std::thread([&server, raw, path] {
      auto tab = server.client();
      tab->Get(path, [raw](const char* data, size_t length) {
        raw->body.append(data, length);
        if (raw->body.find("event: job") != std::string::npos) raw->opened = true;
        return true;
      });
      raw->done = true;
    });
    held.push_back(std::move(stream));
  };
  const auto wait_opened = [&] {
    const auto deadline = Clock::now() + std::chrono::seconds(30);
    for (const auto& stream : held)
      while (!stream->opened && !stream->done && Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    int opened = 0;
    for (const auto& stream : held) opened += stream->opened ? 1 : 0;
    return opened;
  };
  for (int i = 0; i < HELD; ++i) hold_one();
  ASSERT_EQ(wait_opened(), HELD);

  auto health = client->Get("/api/v1/health");
  ASSERT_TRUE(health) << "no worker thread left with " << HELD << " open streams";
  EXPECT_EQ(health->status, 200);
  auto job = client->Get("/api/v1/jobs/" + queued);
  ASSERT_TRUE(job);
  EXPECT_EQ(parse<v1::Job>(job->body).state(), v1::JOB_STATE_QUEUED) << "the streams need a quiet job";

  // Streams that hang up give their place back: more of them than the places left, one after another.
  for (int i = 0; i < 6; ++i) {
    bool got_first = false;
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    while (!got_first && Clock::now() < deadline) {
      auto tab = server.client();
      tab->Get(path, [&](const char* data, size_t length) {
        got_first = std::string(data, length).find("event: job") != std::string::npos;
        return !got_first;
      });
      if (!got_first) std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a 503 until one comes back
    }
    EXPECT_TRUE(got_first) << "stream " << i << " never found a free place";
  }
  for (int i = HELD; i < CAP; ++i) {
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    // The hung-up streams above may still hold their places for one poll (0.25 s).
    while (Clock::now() < deadline) {
      hold_one();
      if (wait_opened() == static_cast<int>(held.size())) break;
      held.back()->reader.join();  // it got 503: the server answered and the reader returned
      held.pop_back();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ASSERT_EQ(wait_opened(), CAP);
  auto refused = client->Get(path);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 503);
  EXPECT_EQ(error_of(refused).first, "UNAVAILABLE");
  EXPECT_NE(error_of(refused).second.find("--http-max-event-streams"), std::string::npos) << error_of(refused).second;
  health = client->Get("/api/v1/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);

  EXPECT_EQ(server.stop(SIGTERM), 0);  // ends every stream with `event: end`
  for (const auto& stream : held) {
    stream->reader.join();
    EXPECT_NE(stream->body.find("event: end"), std::string::npos);
  }
}

TEST(HttpGateway, ServesHttpsWithTheGivenCertificate) {
  ScratchDir scratch;
  const std::string cert = scratch.file("cert.pem"), key = scratch.file("key.pem");
  const std::string openssl = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 "
                              "-subj /CN=localhost -addext subjectAltName=IP:127.0.0.1,DNS:localhost -keyout '" +
                              key + "' -out '" + cert + "' >/dev/null 2>&1";
  if (std::system(openssl.c_str()) != 0) GTEST_SKIP() << "openssl cannot make a test certificate";
  HttpServer server(scratch, {"--quiet", "--workers", "1", "--http-tls-cert", cert, "--http-tls-key", key});
  EXPECT_NE(server.output().find("(https, web root"), std::string::npos) << server.output();
  httplib::SSLClient secure("127.0.0.1", server.http_port());
  secure.set_ca_cert_path(cert.c_str());
  secure.enable_server_certificate_verification(true);
  secure.set_read_timeout(30, 0);
  auto health = secure.Get("/api/v1/health");
  ASSERT_TRUE(health) << httplib::to_string(health.error());
  EXPECT_EQ(health->status, 200);
  EXPECT_EQ(health->body, R"({"status":"ok"})");
  const std::string origin = "https://127.0.0.1:" + std::to_string(server.http_port());
  auto put = secure.Put("/api/v1/materials/soft", {{"Origin", origin}}, R"({"spec":"neo-hookean:mu=0.25"})",
                        "application/json");
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 200) << put->body;
  auto plain_origin = secure.Put("/api/v1/materials/soft", {{"Origin", "http://127.0.0.1:" + std::to_string(server.http_port())}},
                                 R"({"spec":"neo-hookean:mu=0.25"})", "application/json");
  ASSERT_TRUE(plain_origin);
  EXPECT_EQ(plain_origin->status, 403) << "the http:// page is another origin than the https:// server";
  auto plaintext = server.client()->Get("/api/v1/health");
  EXPECT_TRUE(!plaintext || plaintext->status != 200) << "plain HTTP must not be answered on the HTTPS port";

  std::string output;
  EXPECT_EQ(run_server({"--http", "127.0.0.1:0", "--db", ":memory:", "--http-tls-cert", cert}, &output), 2);
  EXPECT_NE(output.find("--http-tls-key"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--http", "127.0.0.1:0", "--db", ":memory:", "--http-tls-cert", key, "--http-tls-key", cert},
                       &output), 1);
  EXPECT_NE(output.find("HTTP TLS"), std::string::npos) << output;
}

TEST(HttpGateway, TokensAreRefusedOverPlaintextOffLoopbackAndMustBeUnique) {
  ScratchDir scratch;
  const std::string tokens = scratch.file("tokens");
  std::ofstream(tokens) << "alice alice-token-0123456789\nbob bob-token-0123456789ab\n";
  // A store that cannot open ends the start after every flag rule has passed (exit 1, naming the store).
  const std::string no_store = scratch.file("no-such-dir") + "/jobs.db";
  std::string output;
  EXPECT_EQ(run_server({"--listen", "0.0.0.0:0", "--token-file", tokens, "--db", no_store}, &output), 1);
  EXPECT_NE(output.find("plaintext gRPC"), std::string::npos) << output;
  EXPECT_NE(output.find("--insecure-plaintext-tokens"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--listen", "0.0.0.0:0", "--token-file", tokens, "--db", no_store, "--insecure-plaintext-tokens"},
                       &output), 1);
  EXPECT_EQ(output.find("plaintext"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--listen", "127.0.0.1:0", "--http", "0.0.0.0:0", "--token-file", tokens, "--db", no_store},
                       &output), 2);
  EXPECT_NE(output.find("plaintext HTTP"), std::string::npos) << output;
  EXPECT_NE(output.find("--insecure-plaintext-tokens"), std::string::npos) << output;
  output.clear();
  EXPECT_EQ(run_server({"--listen", "127.0.0.1:0", "--http", "0.0.0.0:0", "--token-file", tokens, "--db", no_store,
                        "--http-tls-cert", tokens, "--http-tls-key", tokens},
                       &output), 1);
  EXPECT_EQ(output.find("plaintext"), std::string::npos) << output;
  // A name that only looks like loopback is not.
  output.clear();
  EXPECT_EQ(run_server({"--listen", "127.evil.example:0", "--db", ":memory:"}, &output), 1);
  EXPECT_NE(output.find("without --token-file"), std::string::npos) << output;

  // A repeated token would merge two tenants: refused at start, naming the lines, never the token.
  std::ofstream(scratch.file("twice")) << "alice shared-token-0123456789\n# comment\nbob shared-token-0123456789\n";
  output.clear();
  EXPECT_EQ(run_server({"--token-file", scratch.file("twice"), "--db", ":memory:"}, &output), 1);
  EXPECT_NE(output.find("line 3: the same token as line 1"), std::string::npos) << output;
  EXPECT_EQ(output.find("shared-token"), std::string::npos) << "tokens must never be printed: " << output;
  std::ofstream(scratch.file("bad-option")) << "alice alice-token-0123456789 second-token-0123456789\n";
  output.clear();
  EXPECT_EQ(run_server({"--token-file", scratch.file("bad-option"), "--db", ":memory:"}, &output), 1);
  EXPECT_NE(output.find("line 1: only 'raise-priority'"), std::string::npos) << output;
  EXPECT_EQ(output.find("second-token"), std::string::npos) << output;
}

TEST(HttpGateway, OnlyMarkedTenantsRaisePriority) {
  ScratchDir scratch;
  std::ofstream(scratch.file("tokens")) << "boss boss-token-0123456789 raise-priority\nbob bob-token-0123456789ab\n";
  HttpServer server(scratch, {"--quiet", "--workers", "1", "--token-file", scratch.file("tokens")});
  auto client = server.client();
  const httplib::Headers boss = {{"Authorization", "Bearer boss-token-0123456789"}};
  const httplib::Headers bob = {{"Authorization", "Bearer bob-token-0123456789ab"}};
  const auto with_priority = [](int priority) {
    std::string body = simulate_body(sphere_obj(1), R"("volume_ratio":2)");
    body.insert(body.size() - 2, ",\"priority\":" + std::to_string(priority));
    return body;
  };
  auto raised = client->Post("/api/v1/jobs", bob, with_priority(5), "application/json");
  ASSERT_TRUE(raised);
  EXPECT_EQ(raised->status, 403) << raised->body;
  EXPECT_EQ(error_of(raised).first, "PERMISSION_DENIED");
  EXPECT_NE(error_of(raised).second.find("raise-priority"), std::string::npos) << error_of(raised).second;
  EXPECT_FALSE(submit(*client, with_priority(0), bob).empty());
  EXPECT_FALSE(submit(*client, with_priority(-5), bob).empty());
  EXPECT_FALSE(submit(*client, with_priority(5), boss).empty());
}

}  // namespace
}  // namespace balloon::testing
