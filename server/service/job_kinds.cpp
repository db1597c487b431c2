// The list of job kinds and what they share (mesh results, format names).
#include <algorithm>
#include <cstdio>

#include "mesh/mesh_io.hpp"
#include "service/job_kind.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {

namespace v1 = balloon::v1;

const JobKind* job_kind_for(const v1::JobSpec& spec) {
  switch (spec.kind_case()) {
    case v1::JobSpec::kSimulate: return &simulate_kind();
    case v1::JobSpec::kDesign: return &design_kind();
    case v1::JobSpec::kFitMaterial: return &fit_material_kind();
    case v1::JobSpec::KIND_NOT_SET: return nullptr;
  }
  return nullptr;
}

const JobKind* job_kind_named(const std::string& name) {
  for (const JobKind* kind : {&simulate_kind(), &design_kind(), &fit_material_kind()})
    if (name == kind->name()) return kind;
  return nullptr;
}

ServiceStatus JobKind::fill_result(const store::ResultRecord& stored, v1::MeshFormat format,
                                   v1::JobResult* reply) const {
  const Result<TriMesh> rest = store::decode_mesh_blob(stored.rest_mesh);
  const Result<TriMesh> inflated = store::decode_mesh_blob(stored.inflated_mesh);
  if (!rest || !inflated) return ServiceStatus::error(StatusCode::Internal, "stored meshes are unreadable");
  const std::string extension = mesh_format_extension(format);
  reply->set_kind(proto_kind());
  reply->set_converged(stored.converged);
  reply->mutable_rest_mesh()->set_format(format);
  reply->mutable_rest_mesh()->set_data(write_mesh_to_memory(*rest, extension));
  reply->mutable_inflated_mesh()->set_format(format);
  reply->mutable_inflated_mesh()->set_data(write_mesh_to_memory(*inflated, extension));
  reply->set_report_json(stored.report_json);
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

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

bool names_stored_material(const v1::MaterialRef& reference) {
  if (reference.kind_case() != v1::MaterialRef::kName) return false;
  const std::vector<std::string> presets = preset_names();
  return std::find(presets.begin(), presets.end(), reference.name()) == presets.end();
}

}  // namespace balloon::service
