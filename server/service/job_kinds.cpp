// The list of job kinds and what they share (mesh results, reports, format names).
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "jobs/design_job.hpp"
#include "mesh/mesh_io.hpp"
#include "service/job_kind.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {

namespace v1 = balloon::v1;

namespace {

/// Time kept after a time-limited run stops itself, for its results and report (s): a tenth of what is
/// left, within these bounds.
constexpr double RUN_FINISH_MIN_S = 1.0;
constexpr double RUN_FINISH_MAX_S = 30.0;

/// The kind's report message inside `reply`, selected in the `report` oneof.
google::protobuf::Message* report_of(v1::JobKind kind, v1::JobResult* reply) {
  switch (kind) {
    case v1::JOB_KIND_SIMULATE: return reply->mutable_simulate_report();
    case v1::JOB_KIND_DESIGN: return reply->mutable_design_report();
    case v1::JOB_KIND_FIT_MATERIAL: return reply->mutable_fit_report();
    case v1::JOB_KIND_CURVE: return reply->mutable_curve_report();
    default: return nullptr;
  }
}

/// A report stored as JSON before reports were typed (schema version < 4), read into its message. A fit
/// report was one object, or a list for "all"; unknown keys (e.g. the fit's plot_svg) are skipped.
bool read_legacy_report(v1::JobKind kind, std::string json, google::protobuf::Message* report) {
  if (kind == v1::JOB_KIND_FIT_MATERIAL) {
    const std::size_t start = json.find_first_not_of(" \t\r\n");
    json = start != std::string::npos && json[start] == '[' ? "{\"fits\":" + json + "}" : "{\"fits\":[" + json + "]}";
  }
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = true;
  return google::protobuf::util::JsonStringToMessage(json, report, options).ok();
}

/// A design's mold as binary STL: the stored one, or, for a design stored before the server kept molds,
/// built from the rest shape with the report's tube. Empty when the design has no mold.
Result<std::string> mold_stl(const store::ResultRecord& stored, const TriMesh& rest, const v1::DesignReport& report) {
  if (!stored.mold_mesh.empty()) {
    Result<TriMesh> mold = store::decode_mesh_blob(stored.mold_mesh);
    if (!mold) return fail("the stored mold is unreadable");
    return write_mesh_to_memory(*mold, "stl");
  }
  if (!report.has_mold()) return std::string();
  jobs::MoldParameters tube;
  tube.nozzle_vertex = report.mold().nozzle_vertex();
  tube.tube_radius_mm = report.mold().tube_radius_mm();
  tube.tube_length_mm = report.mold().tube_length_mm();
  Result<TriMesh> mold = jobs::design_mold(rest, tube);
  if (!mold) return std::string();  // the report names the tube, but it no longer builds: no mold
  return write_mesh_to_memory(*mold, "stl");
}

}  // namespace

const JobKind* job_kind_for(const v1::JobSpec& spec) {
  switch (spec.kind_case()) {
    case v1::JobSpec::kSimulate:
      return spec.simulate().control_case() == v1::SimulateJob::kCurve ? &curve_kind() : &simulate_kind();
    case v1::JobSpec::kDesign: return &design_kind();
    case v1::JobSpec::kFitMaterial: return &fit_material_kind();
    case v1::JobSpec::KIND_NOT_SET: return nullptr;
  }
  return nullptr;
}

const JobKind* job_kind_named(const std::string& name) {
  for (const JobKind* kind : {&simulate_kind(), &design_kind(), &fit_material_kind(), &curve_kind()})
    if (name == kind->name()) return kind;
  return nullptr;
}

ServiceStatus JobKind::fill_result(const store::ResultRecord& stored, v1::MeshFormat format,
                                   v1::JobResult* reply, bool inflated_mesh_only) const {
  const Result<TriMesh> inflated = store::decode_mesh_blob(stored.inflated_mesh);
  const Result<TriMesh> rest = inflated_mesh_only ? Result<TriMesh>(TriMesh{}) : store::decode_mesh_blob(stored.rest_mesh);
  if (!rest || !inflated) return ServiceStatus::error(StatusCode::Internal, "stored meshes are unreadable");
  const std::string extension = mesh_format_extension(format);
  reply->set_kind(proto_kind());
  reply->set_converged(stored.converged);
  if (!inflated_mesh_only) {
    reply->mutable_rest_mesh()->set_format(format);
    reply->mutable_rest_mesh()->set_data(write_mesh_to_memory(*rest, extension));
  }
  reply->mutable_inflated_mesh()->set_format(format);
  reply->mutable_inflated_mesh()->set_data(write_mesh_to_memory(*inflated, extension));
  if (ServiceStatus report = fill_report(stored, reply); !report.ok()) return report;
  if (proto_kind() == v1::JOB_KIND_DESIGN && !inflated_mesh_only) {
    Result<std::string> mold = mold_stl(stored, *rest, reply->design_report());
    if (!mold) return ServiceStatus::error(StatusCode::Internal, mold.error());
    if (!mold->empty()) {
      reply->mutable_mold_mesh()->set_format(v1::MESH_FORMAT_STL);
      reply->mutable_mold_mesh()->set_data(std::move(*mold));
    }
  }
  return ServiceStatus::success();
}

ServiceStatus JobKind::fill_report(const store::ResultRecord& stored, v1::JobResult* reply) const {
  google::protobuf::Message* report = report_of(proto_kind(), reply);
  if (report == nullptr) return ServiceStatus::error(StatusCode::Internal, "this job kind has no report");
  const bool read = stored.report.empty() ? read_legacy_report(proto_kind(), stored.report_json, report)
                                          : report->ParseFromString(stored.report);
  if (!read) return ServiceStatus::error(StatusCode::Internal, "the stored report is unreadable");
  return ServiceStatus::success();
}

std::string mesh_format_extension(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_OBJ: return "obj";
    case v1::MESH_FORMAT_STL: return "stl";
    case v1::MESH_FORMAT_PLY: return "ply";
    case v1::MESH_FORMAT_OFF: return "off";
    case v1::MESH_FORMAT_GLTF: return "gltf";
    case v1::MESH_FORMAT_GLB: return "glb";
    default: return "";
  }
}

ServiceStatus read_uploaded_mesh(const v1::MeshFile& file, const std::string& field, int max_vertices, TriMesh* mesh) {
  if (file.data().empty()) return ServiceStatus::bad_field(field, field + " is empty");
  const std::string extension = mesh_format_extension(file.format());
  if (extension.empty())
    return ServiceStatus::bad_field(field, field + ".format is missing or unknown (OBJ, STL, PLY, OFF, GLTF, GLB)");
  Result<TriMesh> read = read_mesh_from_memory(file.data(), extension, upload_limits(max_vertices));
  if (!read) {
    return ServiceStatus::field_error(
        is_over_limit_error(read.error()) ? StatusCode::ResourceExhausted : StatusCode::InvalidArgument, field,
        field + ": " + read.error());
  }
  if (max_vertices > 0 && read->vertex_count() > max_vertices)
    return ServiceStatus::field_error(StatusCode::ResourceExhausted, field,
                                      field + " has " + std::to_string(read->vertex_count()) +
                                          " vertices, over this server's limit of " + std::to_string(max_vertices));
  *mesh = std::move(*read);
  return ServiceStatus::success();
}

ServiceStatus bad_fields(const std::vector<jobs::FieldProblem>& problems) {
  std::vector<FieldViolation> violations;
  for (const jobs::FieldProblem& problem : problems) violations.push_back({problem.field, problem.message});
  return ServiceStatus::bad_fields(std::move(violations));
}

double run_budget_s(const RunContext& context) {
  if (!context.deadline) return 0.0;
  const double left_s = std::chrono::duration<double>(*context.deadline - std::chrono::steady_clock::now()).count();
  const double margin_s = std::clamp(0.1 * left_s, RUN_FINISH_MIN_S, RUN_FINISH_MAX_S);
  return std::max(left_s - margin_s, RUN_FINISH_MIN_S);
}

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

std::string format_seconds(double seconds) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), seconds < 100.0 ? "%.2f" : "%.1f", seconds);
  return buffer;
}

bool names_stored_material(const v1::MaterialRef& reference) {
  if (reference.kind_case() != v1::MaterialRef::kName) return false;
  const std::vector<std::string> presets = preset_names();
  return std::find(presets.begin(), presets.end(), reference.name()) == presets.end();
}

}  // namespace balloon::service
