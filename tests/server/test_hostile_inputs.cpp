// The bad-input catalogue (issue 11): one real balloon-server on 127.0.0.1 with two tenants, a low message
// limit and the HTTP gateway, fed hostile inputs one after another. Each has its expected gRPC status and
// a fragment of its message; afterwards the server still answers SERVING on grpc.health.v1, its RSS has
// grown by less than 100 MB, and every hostile-but-valid job it accepted has ended.
#include <gtest/gtest.h>

#include <grpcpp/generic/generic_stub.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "mesh/icosphere.hpp"
#include "mesh/mesh_io.hpp"
#include "scratch_dir.hpp"
#include "server_process.hpp"

// After Eigen: httplib brings in <resolv.h>, whose _res macro breaks Eigen's headers.
#include <httplib.h>

namespace balloon::testing {
namespace {

namespace v1 = balloon::v1;
using Clock = std::chrono::steady_clock;
using Stub = v1::BalloonService::Stub;

const std::string ALICE = "alice-token-0123456789";
const std::string BOB = "bob-token-0123456789ab";
constexpr int MAX_MESSAGE_MB = 8;  // the server's --max-message-mb here: room for the 80k-triangle STL
constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Hostile files.

void append_u32(std::string& out, std::uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<char>((v >> shift) & 0xffU));
}

/// A binary STL of `triangles` triangles whose every coordinate is NaN (welding them was quadratic).
std::string nan_stl(std::uint32_t triangles) {
  std::string out(80, ' ');
  append_u32(out, triangles);
  const std::uint32_t nan_bits = std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN());
  for (std::uint32_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 12; ++k) append_u32(out, nan_bits);
    out += std::string(2, '\0');
  }
  return out;
}

/// A glTF 2.0 tetrahedron whose one buffer has the member `key` (normally "uri") set to `uri`.
std::string gltf_with_uri(const std::string& uri, const std::string& key = "uri") {
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5125,"count":12,"type":"SCALAR"}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":48}],)"
         R"("buffers":[{"byteLength":96,")" + key + R"(":")" + uri + R"("}]})";
}

/// A GLB whose JSON chunk names an external buffer (and that has no BIN chunk).
std::string glb_with_external_buffer(const std::string& uri) {
  std::string json = gltf_with_uri(uri);
  while (json.size() % 4 != 0) json += ' ';
  std::string out = "glTF";
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(20 + json.size()));
  append_u32(out, static_cast<std::uint32_t>(json.size()));
  return out + "JSON" + json;
}

std::string repeat(const std::string& piece, int times) {
  std::string out;
  out.reserve(piece.size() * static_cast<std::size_t>(times));
  for (int i = 0; i < times; ++i) out += piece;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Requests.

std::string small_sphere_obj() { return write_mesh_to_memory(make_icosphere(10.0, 1), "obj"); }

v1::SubmitJobRequest simulate_with_mesh(const std::string& data, v1::MeshFormat format) {
  v1::SubmitJobRequest request;
  v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();
  job->mutable_rest_mesh()->set_data(data);
  job->mutable_rest_mesh()->set_format(format);
  job->mutable_material()->set_name("latex");
  job->set_volume_ratio(2.0);
  // Hostile but valid jobs must end by themselves, soon.
  request.mutable_spec()->set_time_limit_s(3.0);
  return request;
}

v1::SubmitJobRequest good_simulate() { return simulate_with_mesh(small_sphere_obj(), v1::MESH_FORMAT_OBJ); }

v1::SubmitJobRequest good_design() {
  v1::SubmitJobRequest request;
  v1::DesignJob* job = request.mutable_spec()->mutable_design();
  job->mutable_target_mesh()->set_data(small_sphere_obj());
  job->mutable_target_mesh()->set_format(v1::MESH_FORMAT_OBJ);
  job->mutable_material()->set_name("latex");
  job->set_resolution(0);  // never remesh: the catalogue is about the fields, not CGAL
  job->set_volume_ratio(4.0);
  request.mutable_spec()->set_time_limit_s(3.0);
  return request;
}

std::string read_data(const std::string& relative) {
  std::ifstream in(std::string(BALLOON_TEST_DATA_DIR) + "/" + relative, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

v1::SubmitJobRequest good_fit(const std::string& csv = read_data("materials/treloar1944_ut.csv"),
                              const std::string& test = "uniaxial") {
  v1::SubmitJobRequest request;
  v1::FitMaterialJob* job = request.mutable_spec()->mutable_fit_material();
  v1::MeasurementSet* set = job->add_data();
  set->set_csv(csv);
  set->set_test(test);
  job->set_model("neo-hookean");
  request.mutable_spec()->set_time_limit_s(3.0);
  return request;
}

/// A bulge set (pressure rising with the extension ratio) with the given disc radius and thickness.
v1::SubmitJobRequest bulge_fit(double radius_mm, double thickness_mm) {
  v1::SubmitJobRequest request = good_fit("pressure_kpa,extension_ratio\n0,1\n2,1.1\n3,1.3\n3.5,1.6\n", "bulge");
  request.mutable_spec()->mutable_fit_material()->mutable_data(0)->set_radius_mm(radius_mm);
  request.mutable_spec()->mutable_fit_material()->mutable_data(0)->set_thickness_mm(thickness_mm);
  return request;
}

// ---------------------------------------------------------------------------------------------
// The server, seen from outside.

/// PID of the balloon-server using `db_path` (its command line names it), or -1.
int server_pid(const std::string& db_path) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    const std::string cmdline{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (cmdline.find(BALLOON_SERVER_PATH) == 0 && cmdline.find(db_path) != std::string::npos) return std::stoi(name);
  }
  return -1;
}

/// VmRSS of a process in kB (from /proc/PID/status), or -1.
long rss_kb(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

/// grpc.health.v1.Health/Check for the whole server (service ""): the status number (1 = SERVING), or -1.
int health_status(const std::string& address) {
  grpc::GenericStub generic(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::CompletionQueue queue;
  grpc::Slice empty("");
  const grpc::ByteBuffer request(&empty, 1);  // HealthCheckRequest{service: ""} encodes to no bytes
  auto call = generic.PrepareUnaryCall(&context, "/grpc.health.v1.Health/Check", request, &queue);
  call->StartCall();
  grpc::ByteBuffer reply;
  grpc::Status status;
  call->Finish(&reply, &status, reinterpret_cast<void*>(1));
  void* tag = nullptr;
  bool ok = false;
  if (!queue.Next(&tag, &ok) || !ok || !status.ok()) {
    ADD_FAILURE() << "grpc.health.v1.Health/Check: " << status.error_message();
    return -1;
  }
  std::vector<grpc::Slice> slices;
  if (!reply.Dump(&slices).ok()) return -1;
  std::string bytes;
  for (const grpc::Slice& slice : slices) bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  // HealthCheckResponse{status = 1}: field 1, varint.
  return bytes.size() == 2 && bytes[0] == 0x08 ? bytes[1] : (bytes.empty() ? 0 : -1);
}

grpc::Status submit(Stub& stub, const v1::SubmitJobRequest& request, std::string* job_id, const std::string& token = ALICE) {
  grpc::ClientContext context;
  add_token(context, token);
  v1::SubmitJobResponse reply;
  const grpc::Status status = stub.SubmitJob(&context, request, &reply);
  if (status.ok()) *job_id = reply.job().id();
  return status;
}

grpc::Status get_job(Stub& stub, const std::string& id, const std::string& token, v1::Job* job = nullptr) {
  grpc::ClientContext context;
  add_token(context, token);
  v1::GetJobRequest request;
  request.set_job_id(id);
  v1::Job reply;
  const grpc::Status status = stub.GetJob(&context, request, &reply);
  if (job != nullptr) *job = reply;
  return status;
}

grpc::Status cancel_job(Stub& stub, const std::string& id, const std::string& token) {
  grpc::ClientContext context;
  add_token(context, token);
  v1::CancelJobRequest request;
  request.set_job_id(id);
  v1::Job reply;
  return stub.CancelJob(&context, request, &reply);
}

grpc::Status get_result(Stub& stub, const std::string& id, const std::string& token) {
  grpc::ClientContext context;
  add_token(context, token);
  v1::GetResultRequest request;
  request.set_job_id(id);
  v1::JobResult reply;
  return stub.GetResult(&context, request, &reply);
}

grpc::Status watch_first(Stub& stub, const std::string& id, const std::string& token) {
  grpc::Status status;
  watch_all(stub, id, &status, token);
  return status;
}

bool is_final(v1::JobState state) {
  return state == v1::JOB_STATE_COMPLETED || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED;
}

// ---------------------------------------------------------------------------------------------

struct Case {
  std::string name;
  std::function<grpc::Status()> call;
  grpc::StatusCode code;
  std::string fragment;  ///< in the status message ("" for none expected)
};

TEST(HostileInputs, CatalogueGetsItsStatusesAndTheServerStaysServingAndSmall) {
  ScratchDir scratch("balloon-hostile");
  std::ofstream(scratch.file("tokens")) << "alice " << ALICE << "\nbob " << BOB << "\n";
  const std::string db = scratch.file("jobs.db");
  ServerProcess server(db, {"--workers", "1", "--token-file", scratch.file("tokens"), "--max-message-mb",
                            std::to_string(MAX_MESSAGE_MB), "--http", "127.0.0.1:0"});
  auto stub = server.stub();
  const int pid = server_pid(db);
  ASSERT_GT(pid, 0);

  // A finished job of Alice's for the routes that need one, and one of her materials.
  std::string alice_job;
  ASSERT_TRUE(submit(*stub, good_simulate(), &alice_job).ok());
  for (auto deadline = Clock::now() + std::chrono::seconds(30); Clock::now() < deadline;) {
    v1::Job job;
    ASSERT_TRUE(get_job(*stub, alice_job, ALICE, &job).ok());
    if (is_final(job.state())) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  {
    grpc::ClientContext context;
    add_token(context, ALICE);
    v1::PutMaterialRequest request;
    request.mutable_material()->set_name("alice-rubber");
    request.mutable_material()->set_spec("neo-hookean:mu=0.31");
    v1::Material reply;
    ASSERT_TRUE(stub->PutMaterial(&context, request, &reply).ok());
  }
  const long rss_before_kb = rss_kb(pid);
  ASSERT_GT(rss_before_kb, 0);

  std::vector<Case> cases;
  std::vector<std::string> accepted;  // jobs the catalogue expects to be accepted: they must end
  const auto submit_case = [&](const std::string& name, const v1::SubmitJobRequest& request, grpc::StatusCode code,
                               const std::string& fragment) {
    cases.push_back({name, [&, request] {
                       std::string id;
                       const grpc::Status status = submit(*stub, request, &id);
                       if (status.ok()) accepted.push_back(id);
                       return status;
                     },
                     code, fragment});
  };
  const auto mesh_case = [&](const std::string& name, const std::string& data, v1::MeshFormat format,
                             grpc::StatusCode code, const std::string& fragment) {
    submit_case(name, simulate_with_mesh(data, format), code, fragment);
  };
  using grpc::StatusCode;

  // External glTF URIs: the server reads only the uploaded bytes, and says which name it refused.
  mesh_case("glTF uri absolute path", gltf_with_uri("/etc/passwd"), v1::MESH_FORMAT_GLTF, StatusCode::INVALID_ARGUMENT,
            "uri '/etc/passwd'");
  mesh_case("glTF uri file://", gltf_with_uri("file:///etc/hostname"), v1::MESH_FORMAT_GLTF,
            StatusCode::INVALID_ARGUMENT, "uri 'file:///etc/hostname'");
  mesh_case("glTF uri relative", gltf_with_uri("../../buffer.bin"), v1::MESH_FORMAT_GLTF, StatusCode::INVALID_ARGUMENT,
            "uri '../../buffer.bin'");
  mesh_case("glTF uri /dev/zero", gltf_with_uri("/dev/zero"), v1::MESH_FORMAT_GLTF, StatusCode::INVALID_ARGUMENT,
            "uri '/dev/zero'");
  mesh_case("glTF uri key spelled with a \\u escape", gltf_with_uri("/etc/passwd", "\\u0075ri"), v1::MESH_FORMAT_GLTF,
            StatusCode::INVALID_ARGUMENT, "outside the upload ('/etc/passwd'); only");
  mesh_case("GLB with an external buffer", glb_with_external_buffer("/etc/passwd"), v1::MESH_FORMAT_GLB,
            StatusCode::INVALID_ARGUMENT, "uri '/etc/passwd'");
  mesh_case("glTF nested 200000 deep (assimp's JSON parser recursed off the stack)",
            R"({"asset":{"version":"2.0"},"extras":)" + std::string(200000, '[') + std::string(200000, ']') + "}",
            v1::MESH_FORMAT_GLTF, StatusCode::INVALID_ARGUMENT, "nested deeper than");
  {
    std::string chain = R"({"asset":{"version":"2.0"},"nodes":[)";
    for (int i = 0; i < 100000; ++i) chain += R"({"children":[)" + std::to_string(i + 1) + "]},";
    mesh_case("glTF node tree 100000 deep (assimp recursed off the stack)", chain + "{}]}", v1::MESH_FORMAT_GLTF,
              StatusCode::INVALID_ARGUMENT, "more than 4096 objects");
  }
  mesh_case("glTF that is not JSON", "{\"asset\":", v1::MESH_FORMAT_GLTF, StatusCode::INVALID_ARGUMENT, "rest_mesh");

  // Header bombs: counts that the bytes cannot hold are refused before any allocation.
  mesh_case("OFF header bomb", "OFF\n100000000 200000000 0\n0 0 0\n", v1::MESH_FORMAT_OFF, StatusCode::INVALID_ARGUMENT,
            "the header declares 100000000 vertices");
  mesh_case("OFF counts past int", "OFF\n4000000000 4000000000 0\n", v1::MESH_FORMAT_OFF, StatusCode::INVALID_ARGUMENT,
            "bad vertex and face counts");
  mesh_case("ASCII PLY header bomb",
            "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 4000000000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n",
            v1::MESH_FORMAT_PLY, StatusCode::INVALID_ARGUMENT, "declares 4000000000 vertex elements");
  mesh_case("binary PLY header bomb",
            "ply\nformat binary_little_endian 1.0\nelement vertex 100000\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" + std::string(64, '\0'),
            v1::MESH_FORMAT_PLY, StatusCode::INVALID_ARGUMENT, "declares 100000 vertex elements");
  mesh_case("binary STL whose count exceeds its bytes", [] {
    std::string stl = nan_stl(2);
    stl[80] = stl[81] = stl[82] = stl[83] = '\xff';
    return stl;
  }(), v1::MESH_FORMAT_STL, StatusCode::INVALID_ARGUMENT, "rest_mesh");

  // Inputs on which assimp 5.2 loops for ever or leaks (found by tests/fuzz): refused before assimp sees them.
  mesh_case("PLY header with a nameless element (assimp loops)", "ply\nformat ascii 1.0\nelement 1\n1 0.125 0.625\nend_header\n",
            v1::MESH_FORMAT_PLY, StatusCode::INVALID_ARGUMENT, "bad PLY header: line 3");
  mesh_case("ASCII PLY with a word among its numbers",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 x0\n3 0 1 2\n",
            v1::MESH_FORMAT_PLY, StatusCode::INVALID_ARGUMENT, "'x0' is not a float");
  mesh_case("glTF with bad base64", gltf_with_uri("data:application/octet-stream;base64,AA*A"), v1::MESH_FORMAT_GLTF,
            StatusCode::INVALID_ARGUMENT, "bad base64");
  {
    // Found by tests/fuzz: a byteStride taking the index accessor past its view; assimp leaked the faces it had allocated.
    std::string strided = gltf_with_uri("data:application/octet-stream;base64," + std::string(128, 'A'));
    const std::string view = R"("byteOffset":48,"byteLength":48})";
    strided.replace(strided.find(view), view.size(), R"("byteOffset":48,"byteLength":48,"byteStride":8})");
    mesh_case("glTF index accessor strided past its buffer view (assimp leaked)", strided, v1::MESH_FORMAT_GLTF,
              StatusCode::INVALID_ARGUMENT, "accessor 1 (12 elements of 4 bytes, 8 apart, from offset 0) does not fit in buffer view 1");
  }

  // Non-finite coordinates: refused before the weld, in time linear in the file.
  for (const std::uint32_t triangles : {5000u, 20000u, 80000u}) {
    mesh_case("NaN STL of " + std::to_string(triangles) + " triangles", nan_stl(triangles), v1::MESH_FORMAT_STL,
              StatusCode::INVALID_ARGUMENT, "non-finite coordinate");
  }
  mesh_case("ASCII STL with nan", "solid x\nfacet normal 0 0 0\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
            "endloop\nendfacet\nendsolid x\n", v1::MESH_FORMAT_STL, StatusCode::INVALID_ARGUMENT, "rest_mesh");
  mesh_case("OBJ coordinate 1e999", "v 1e999 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", v1::MESH_FORMAT_OBJ,
            StatusCode::INVALID_ARGUMENT, "bad vertex coordinate '1e999'");
  mesh_case("OBJ index past long", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n", v1::MESH_FORMAT_OBJ,
            StatusCode::INVALID_ARGUMENT, "bad vertex reference");

  // A face bomb: 4 vertices, 300k copies of one face. The message names the edge and the count, briefly.
  mesh_case("face bomb", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + repeat("f 1 2 3\n", 300000), v1::MESH_FORMAT_OBJ,
            StatusCode::INVALID_ARGUMENT, "non-manifold edge");

  // Every numeric field of SimulateJob: NaN, inf, -1, 1e308, 0.
  const double hostile[] = {NaN, INF, -1.0, 1e308, 0.0};
  const auto number_name = [](double v) {
    return std::isnan(v) ? std::string("NaN") : std::isinf(v) ? std::string("inf") : v == 1e308 ? std::string("1e308") : std::to_string(static_cast<int>(v));
  };
  for (const double v : hostile) {
    // thickness_mm 0 means the default; 1e308 is a positive number but no thin sheet on this mesh.
    v1::SubmitJobRequest thickness = good_simulate();
    thickness.mutable_spec()->mutable_simulate()->set_thickness_mm(v);
    submit_case("simulate thickness_mm " + number_name(v), thickness, v == 0.0 ? StatusCode::OK : StatusCode::INVALID_ARGUMENT,
                v == 0.0 ? "" : v == 1e308 ? "thin-sheet model" : "thickness must be a positive number of mm");
    // size_mm 0 keeps the mesh's size; beyond 1e6 mm (1e308) it is a unit mistake.
    v1::SubmitJobRequest size = good_simulate();
    size.mutable_spec()->mutable_simulate()->set_size_mm(v);
    submit_case("simulate size_mm " + number_name(v), size, v == 0.0 ? StatusCode::OK : StatusCode::INVALID_ARGUMENT,
                v == 0.0 ? "" : "size must be a number of mm up to");
    v1::SubmitJobRequest pressure = good_simulate();
    pressure.mutable_spec()->mutable_simulate()->set_pressure_kpa(v);
    // 1e308 is refused at submit, as a curve's range is (a ratio of 1e308 came back "non-finite residual").
    submit_case("simulate pressure_kpa " + number_name(v), pressure, StatusCode::INVALID_ARGUMENT,
                "pressure must be a positive number of kPa up to 1e+06");
    v1::SubmitJobRequest ratio = good_simulate();
    ratio.mutable_spec()->mutable_simulate()->set_volume_ratio(v);
    submit_case("simulate volume_ratio " + number_name(v), ratio, StatusCode::INVALID_ARGUMENT,
                "volume ratio must be a positive number up to 1e+06");
  }
  // SimulateJob.curve (a curve job): each end of the range and the point count.
  const auto good_curve = [] {
    v1::SubmitJobRequest request = good_simulate();
    v1::CurveSweep* curve = request.mutable_spec()->mutable_simulate()->mutable_curve();
    curve->mutable_volume_ratio_range()->set_from(1.5);
    curve->mutable_volume_ratio_range()->set_to(4.0);
    curve->set_points(3);
    return request;
  };
  submit_case("curve 1.5:4 in 3 points", good_curve(), StatusCode::OK, "");
  for (const double v : hostile) {
    v1::SubmitJobRequest from = good_curve();
    from.mutable_spec()->mutable_simulate()->mutable_curve()->mutable_volume_ratio_range()->set_from(v);
    submit_case("curve volume_ratio_range.from " + number_name(v), from, StatusCode::INVALID_ARGUMENT, "range");
    v1::SubmitJobRequest to = good_curve();
    to.mutable_spec()->mutable_simulate()->mutable_curve()->mutable_volume_ratio_range()->set_to(v);
    submit_case("curve volume_ratio_range.to " + number_name(v), to, StatusCode::INVALID_ARGUMENT, "range");
    v1::SubmitJobRequest pressure = good_curve();
    pressure.mutable_spec()->mutable_simulate()->mutable_curve()->mutable_pressure_range()->set_from(v);
    pressure.mutable_spec()->mutable_simulate()->mutable_curve()->mutable_pressure_range()->set_to(10.0);
    submit_case("curve pressure_range.from " + number_name(v), pressure, StatusCode::INVALID_ARGUMENT, "range");
  }
  for (const int points : {0, -1, 1, 1001, std::numeric_limits<int>::max(), std::numeric_limits<int>::min()}) {
    v1::SubmitJobRequest request = good_curve();
    request.mutable_spec()->mutable_simulate()->mutable_curve()->set_points(points);
    submit_case("curve points " + std::to_string(points), request, StatusCode::INVALID_ARGUMENT,
                "points must be between 2 and 1000");
  }
  // Every numeric field of DesignJob.
  for (const double v : hostile) {
    v1::SubmitJobRequest thickness = good_design();
    thickness.mutable_spec()->mutable_design()->set_thickness_mm(v);
    submit_case("design thickness_mm " + number_name(v), thickness, v == 0.0 ? StatusCode::OK : StatusCode::INVALID_ARGUMENT,
                v == 0.0 ? "" : v == 1e308 ? "thin-sheet model" : "thickness must be a positive number of mm");
    v1::SubmitJobRequest size = good_design();
    size.mutable_spec()->mutable_design()->set_size_mm(v);
    // As simulate's: 0 keeps the target's size, and 1e308 mm is a unit mistake refused at submit.
    submit_case("design size_mm " + number_name(v), size, v == 0.0 ? StatusCode::OK : StatusCode::INVALID_ARGUMENT,
                v == 0.0 ? "" : "size must be a number of mm up to");
    v1::SubmitJobRequest scale = good_design();
    scale.mutable_spec()->mutable_design()->set_scale(v);
    // 1e308 is no start: the balloon must start smaller than its target (it ended start_failed in the job).
    submit_case("design scale " + number_name(v), scale, StatusCode::INVALID_ARGUMENT, "scale must be a number of at least");
    v1::SubmitJobRequest ratio = good_design();
    ratio.mutable_spec()->mutable_design()->set_volume_ratio(v);
    // 1e308 is refused at submit: no rubber inflates past 1000-fold (it failed deep in the solver before).
    submit_case("design volume_ratio " + number_name(v), ratio, StatusCode::INVALID_ARGUMENT,
                "volume ratio must be a positive number");
    v1::SubmitJobRequest time = good_design();
    time.mutable_spec()->mutable_design()->set_max_time_s(v);
    const bool time_valid = v == 0.0 || v == 1e308;
    submit_case("design max_time_s " + number_name(v), time, time_valid ? StatusCode::OK : StatusCode::INVALID_ARGUMENT,
                time_valid ? "" : "max time must be a number of s >= 0");
  }
  // A sheet far thinner than any rubber (1e-300 mm "converged" in 0 Newton steps: every force rounded to 0),
  // a start no smaller than its target (scale 1, volume ratio 1): refused at submit, not failed in the job.
  for (const double thin : {1e-300, 9e-4}) {
    v1::SubmitJobRequest simulate = good_simulate();
    simulate.mutable_spec()->mutable_simulate()->set_thickness_mm(thin);
    submit_case("simulate thickness_mm " + std::to_string(thin), simulate, StatusCode::INVALID_ARGUMENT, "at least 0.001");
    v1::SubmitJobRequest design = good_design();
    design.mutable_spec()->mutable_design()->set_thickness_mm(thin);
    submit_case("design thickness_mm " + std::to_string(thin), design, StatusCode::INVALID_ARGUMENT, "at least 0.001");
  }
  // A mesh a kilometre or more across read as mm (a file in micrometres): simulate "converged" at 1e30 mm
  // and 3.8e-28 kPa. Refused at submit like size_mm above 1e6, naming the size and the remedy.
  const std::string huge_sphere = write_mesh_to_memory(make_icosphere(1e29, 1), "obj");
  const std::string too_large = "mm across (bounding-box diagonal), more than 1e+06 mm (a kilometre)";
  submit_case("simulate a 1e30 mm mesh", simulate_with_mesh(huge_sphere, v1::MESH_FORMAT_OBJ), StatusCode::INVALID_ARGUMENT,
              too_large);
  v1::SubmitJobRequest huge_design = good_design();
  huge_design.mutable_spec()->mutable_design()->mutable_target_mesh()->set_data(huge_sphere);
  submit_case("design a 1e30 mm target", huge_design, StatusCode::INVALID_ARGUMENT, too_large);
  v1::SubmitJobRequest unit_scale = good_design();
  unit_scale.mutable_spec()->mutable_design()->set_scale(1.0);
  submit_case("design scale 1", unit_scale, StatusCode::INVALID_ARGUMENT, "below 1");
  v1::SubmitJobRequest unit_ratio = good_design();
  unit_ratio.mutable_spec()->mutable_design()->set_volume_ratio(1.0);
  submit_case("design volume_ratio 1", unit_ratio, StatusCode::INVALID_ARGUMENT, "above 1");
  for (const int v : {0, -1, 49, std::numeric_limits<int>::max(), std::numeric_limits<int>::min()}) {
    v1::SubmitJobRequest resolution = good_design();
    resolution.mutable_spec()->mutable_design()->set_resolution(v);
    // 0 keeps the target's mesh; a negative count has no meaning (there is no sentinel on the wire).
    const StatusCode code = v == 0 ? StatusCode::OK
                            : v == std::numeric_limits<int>::max() ? StatusCode::RESOURCE_EXHAUSTED
                                                                   : StatusCode::INVALID_ARGUMENT;
    submit_case("design resolution " + std::to_string(v), resolution, code,
                v == 0 ? "" : v == 49 ? "resolution must be at least 50" : v < 0 ? "resolution must be >= 0"
                                                                                 : "over this server's limit");
  }
  for (const int v : {-1, 101, std::numeric_limits<int>::max()}) {
    v1::SubmitJobRequest samples = good_design();
    samples.mutable_spec()->mutable_design()->set_tolerance_samples(v);
    submit_case("design tolerance_samples " + std::to_string(v), samples, StatusCode::INVALID_ARGUMENT,
                "tolerance samples must be within 0..100");
  }
  // FitMaterialJob: the bulge set's radius and thickness, and numbers in the CSV itself.
  for (const double v : hostile) {
    if (v == 1e308) continue;  // a 1e308 mm disc is a valid (silly) disc: accepted below once
    submit_case("fit bulge radius_mm " + number_name(v), bulge_fit(v, 1.0), StatusCode::INVALID_ARGUMENT, "radius");
    submit_case("fit bulge thickness_mm " + number_name(v), bulge_fit(20.0, v), StatusCode::INVALID_ARGUMENT, "thickness");
  }
  submit_case("fit CSV with nan", good_fit("stretch,nominal_stress_MPa\n1.1,nan\n1.2,0.2\n"), StatusCode::INVALID_ARGUMENT,
              "'nan' is not a finite number");
  submit_case("fit CSV with 1e999", good_fit("stretch,nominal_stress_MPa\n1e999,0.1\n1.2,0.2\n"),
              StatusCode::INVALID_ARGUMENT, "'1e999' is not a finite number");
  submit_case("fit CSV with a 1 MB cell", good_fit("stretch,nominal_stress_MPa\n1.1," + std::string(1 << 20, '7') + "x\n"),
              StatusCode::INVALID_ARGUMENT, "...' is not a number");
  // JobSpec's own numbers.
  for (const double v : {NaN, INF, -1.0}) {
    v1::SubmitJobRequest limit = good_simulate();
    limit.mutable_spec()->set_time_limit_s(v);
    submit_case("time_limit_s " + number_name(v), limit, StatusCode::INVALID_ARGUMENT, "time_limit_s must be a finite number");
  }
  for (const int v : {101, -101, std::numeric_limits<int>::max(), std::numeric_limits<int>::min()}) {
    v1::SubmitJobRequest priority = good_simulate();
    priority.mutable_spec()->set_priority(v);
    submit_case("priority " + std::to_string(v), priority, StatusCode::INVALID_ARGUMENT, "priority must be within -100..100");
  }
  cases.push_back({"ListJobs page_size 2^31-1", [&] {
                     grpc::ClientContext context;
                     add_token(context, ALICE);
                     v1::ListJobsRequest request;
                     request.set_page_size(std::numeric_limits<int>::max());
                     v1::ListJobsResponse reply;
                     return stub->ListJobs(&context, request, &reply);
                   },
                   StatusCode::INVALID_ARGUMENT, "page_size must be within 1..1000"});
  cases.push_back({"ListJobs page_token past int64", [&] {
                     grpc::ClientContext context;
                     add_token(context, ALICE);
                     v1::ListJobsRequest request;
                     request.set_page_token("99999999999999999999999");
                     v1::ListJobsResponse reply;
                     return stub->ListJobs(&context, request, &reply);
                   },
                   StatusCode::INVALID_ARGUMENT, "page_token is not one this server gave out"});

  // An upload just over --max-message-mb: refused by gRPC before the service sees it.
  {
    v1::SubmitJobRequest oversized = good_simulate();
    oversized.mutable_spec()->mutable_simulate()->mutable_rest_mesh()->mutable_data()->append(
        (static_cast<std::size_t>(MAX_MESSAGE_MB) << 20) + 1024, '#');
    submit_case("upload over --max-message-mb", oversized, StatusCode::RESOURCE_EXHAUSTED, "");
  }

  // A 100 kB job id: NOT_FOUND on every job route, its message quoting only the start of the id.
  const std::string huge_id(100 * 1024, 'j');
  cases.push_back({"GetJob 100 kB id", [&] { return get_job(*stub, huge_id, ALICE); }, StatusCode::NOT_FOUND, "no job 'jjjj"});
  cases.push_back({"CancelJob 100 kB id", [&] { return cancel_job(*stub, huge_id, ALICE); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"GetResult 100 kB id", [&] { return get_result(*stub, huge_id, ALICE); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"WatchJob 100 kB id", [&] { return watch_first(*stub, huge_id, ALICE); }, StatusCode::NOT_FOUND, "no job"});

  // Cross-tenant access on every job route: Bob sees Alice's job as missing.
  cases.push_back({"Bob GetJob on Alice's job", [&] { return get_job(*stub, alice_job, BOB); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"Bob CancelJob on Alice's job", [&] { return cancel_job(*stub, alice_job, BOB); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"Bob GetResult on Alice's job", [&] { return get_result(*stub, alice_job, BOB); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"Bob WatchJob on Alice's job", [&] { return watch_first(*stub, alice_job, BOB); }, StatusCode::NOT_FOUND, "no job"});
  cases.push_back({"Bob ListJobs sees none of Alice's", [&] {
                     grpc::ClientContext context;
                     add_token(context, BOB);
                     v1::ListJobsResponse reply;
                     const grpc::Status status = stub->ListJobs(&context, v1::ListJobsRequest(), &reply);
                     if (status.ok() && reply.jobs_size() != 0) return grpc::Status(grpc::StatusCode::INTERNAL, "Bob lists Alice's jobs");
                     return status;
                   },
                   StatusCode::OK, ""});
  cases.push_back({"Bob GetMaterial of Alice's", [&] {
                     grpc::ClientContext context;
                     add_token(context, BOB);
                     v1::GetMaterialRequest request;
                     request.set_name("alice-rubber");
                     v1::Material reply;
                     return stub->GetMaterial(&context, request, &reply);
                   },
                   StatusCode::NOT_FOUND, "alice-rubber"});
  cases.push_back({"Bob DeleteMaterial of Alice's", [&] {
                     grpc::ClientContext context;
                     add_token(context, BOB);
                     v1::DeleteMaterialRequest request;
                     request.set_name("alice-rubber");
                     v1::DeleteMaterialResponse reply;
                     return stub->DeleteMaterial(&context, request, &reply);
                   },
                   StatusCode::NOT_FOUND, "alice-rubber"});
  cases.push_back({"Bob simulates with Alice's material", [&] {
                     v1::SubmitJobRequest request = good_simulate();
                     request.mutable_spec()->mutable_simulate()->mutable_material()->set_name("alice-rubber");
                     std::string id;
                     return submit(*stub, request, &id, BOB);
                   },
                   StatusCode::INVALID_ARGUMENT, "alice-rubber"});
  cases.push_back({"no token", [&] { return get_job(*stub, alice_job, ""); }, StatusCode::UNAUTHENTICATED, ""});
  cases.push_back({"unknown token", [&] { return get_job(*stub, alice_job, "mallory-token-0123456789"); },
                   StatusCode::UNAUTHENTICATED, ""});

  // Malformed JSON through the HTTP gateway (its error body carries the gRPC code name).
  httplib::Client http("127.0.0.1", server.http_port());
  http.set_read_timeout(10, 0);
  const httplib::Headers alice_http = {{"Authorization", "Bearer " + ALICE}};
  const auto http_case = [&](const std::string& name, const std::string& body, const std::string& fragment) {
    cases.push_back({name, [&, body] {
                       const auto response = http.Post("/api/v1/jobs", alice_http, body, "application/json");
                       if (!response) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "no HTTP response");
                       // 400 is INVALID_ARGUMENT; the body is {"error":{"code","message"}}.
                       return grpc::Status(response->status == 400 ? grpc::StatusCode::INVALID_ARGUMENT : grpc::StatusCode::UNKNOWN,
                                           std::to_string(response->status) + " " + response->body.substr(0, 500));
                     },
                     StatusCode::INVALID_ARGUMENT, fragment});
  };
  http_case("HTTP: truncated JSON", R"({"spec":{"simulate":{"restMesh":)", "INVALID_ARGUMENT");
  http_case("HTTP: JSON of the wrong type", R"({"spec":{"priority":"high"}})", "INVALID_ARGUMENT");
  http_case("HTTP: 10000 nested arrays", "{\"spec\":" + std::string(10000, '[') + std::string(10000, ']') + "}",
            "INVALID_ARGUMENT");
  http_case("HTTP: not JSON at all", std::string("\xff\xfe\x00garbage", 10), "INVALID_ARGUMENT");

  ASSERT_GE(cases.size(), 40u);
  for (const Case& c : cases) {
    const auto start = Clock::now();
    const grpc::Status status = c.call();
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    EXPECT_EQ(status.error_code(), c.code) << c.name << ": " << status.error_message().substr(0, 300);
    EXPECT_NE(status.error_message().find(c.fragment), std::string::npos) << c.name << ": " << status.error_message().substr(0, 300);
    // Messages are one bounded line (the face bomb's once listed all 300k faces).
    EXPECT_LT(status.error_message().size(), 1000u) << c.name;
    // Nothing hostile is slow: the 80k-triangle NaN STL took 81 s while the weld was quadratic.
    EXPECT_LT(seconds, 10.0) << c.name;
    if (seconds > 0.05 || c.name.rfind("NaN STL", 0) == 0) std::printf("%s: %.3f s\n", c.name.c_str(), seconds);
  }

  // Every hostile-but-valid job ends by itself (time limit 3 s each, one worker).
  for (const std::string& id : accepted) {
    v1::Job job;
    for (auto deadline = Clock::now() + std::chrono::seconds(20); Clock::now() < deadline;) {
      ASSERT_TRUE(get_job(*stub, id, ALICE, &job).ok());
      if (is_final(job.state())) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    EXPECT_TRUE(is_final(job.state())) << job.summary() << " is still " << v1::JobState_Name(job.state());
    std::printf("accepted: %s -> %s converged=%d %s\n", job.summary().c_str(), v1::JobState_Name(job.state()).c_str(), job.converged(),
                job.error().substr(0, 120).c_str());
  }

  EXPECT_EQ(health_status(server.address()), 1) << "grpc.health.v1 is not SERVING after the catalogue";
  const long rss_after_kb = rss_kb(pid);
  std::printf("catalogue: %zu hostile inputs, %zu accepted jobs ended; RSS %ld kB -> %ld kB\n", cases.size(),
              accepted.size(), rss_before_kb, rss_after_kb);
  EXPECT_LT(rss_after_kb - rss_before_kb, 100 * 1024) << "RSS grew from " << rss_before_kb << " kB to " << rss_after_kb << " kB";
  // Alice's job and material are untouched by Bob's attempts.
  v1::Job job;
  ASSERT_TRUE(get_job(*stub, alice_job, ALICE, &job).ok());
  EXPECT_EQ(job.state(), v1::JOB_STATE_COMPLETED);
}

}  // namespace
}  // namespace balloon::testing
