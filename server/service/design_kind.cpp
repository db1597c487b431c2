// The design job kind: the inverse design of a target (jobs/design_job), storing the rest, inflated and
// mold meshes and the report.
#include <algorithm>
#include <cstdio>

#include "jobs/design_job.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "service/job_kind.hpp"
#include "service/job_reports.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;

/// prepare_target's smallest resolution (vertices) other than 0.
constexpr int MIN_REMESH_RESOLUTION = 100;

/// A design request decoded and checked, its target not yet prepared (no remeshing).
struct DecodedDesign {
  TriMesh target;
  Material material;
  jobs::DesignParameters parameters;
};

/// A nozzle centre that cannot be on the target's surface, found before remeshing: empty, or the message
/// prepare_design gives on the worker. `target` is the checked (closed, manifold) mesh as uploaded.
std::string nozzle_problem(TriMesh target, const jobs::DesignParameters& parameters) {
  if (parameters.nozzle.empty()) return "";
  const Result<NozzleSpec> nozzle = parse_nozzle(parameters.nozzle);
  if (!nozzle || nozzle->automatic) return "";
  if (parameters.size_mm > 0.0) scale_to_diagonal(target.vertices, parameters.size_mm);
  // A point on the surface lies within one edge of a vertex; remeshing moves the vertices, not the
  // surface. So only a centre farther than the longest edge is judged now, by the worker's own rule.
  double longest_edge = 0.0;
  for (int f = 0; f < target.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      longest_edge = std::max(longest_edge, (target.vertices.row(target.faces(f, k)) -
                                             target.vertices.row(target.faces(f, (k + 1) % 3))).norm());
  const double gap = (target.vertices.rowwise() - nozzle->center.transpose()).rowwise().norm().minCoeff();
  if (gap <= longest_edge) return "";
  const Result<NozzleSelection> selection = select_nozzle(target, *nozzle);
  return selection ? "" : "nozzle: " + selection.error();
}

/// Decodes and checks a design job: the mesh (within `max_vertices`), the material and the parameters.
/// Cheap: the target is read and, with `check_mesh`, checked closed and manifold, but not remeshed.
ServiceStatus decode_design(const v1::DesignJob& job, const std::string& tenant, int max_vertices, bool check_mesh,
                            MaterialHandler& materials, DecodedDesign* decoded) {
  TriMesh mesh;
  if (ServiceStatus read = read_uploaded_mesh(job.target_mesh(), "target_mesh", max_vertices, &mesh); !read.ok())
    return read;
  Result<Material> material = materials.resolve(tenant, job.material());
  if (!material) return ServiceStatus::bad_field("material", "material: " + material.error());

  jobs::DesignParameters& parameters = decoded->parameters;
  parameters.thickness_mm = job.thickness_mm() == 0.0 ? jobs::DEFAULT_THICKNESS_MM : job.thickness_mm();
  parameters.size_mm = job.size_mm();
  // Absent: the default remesh target; 0 keeps the target's mesh, on the wire as in jobs::DesignParameters.
  parameters.resolution = job.has_resolution() ? job.resolution() : jobs::DEFAULT_DESIGN_RESOLUTION;
  if (job.inflation_case() == v1::DesignJob::kScale) parameters.scale = job.scale();
  if (job.inflation_case() == v1::DesignJob::kVolumeRatio) parameters.volume_ratio = job.volume_ratio();
  parameters.method = job.method();
  parameters.nozzle = job.nozzle();
  parameters.max_time_s = job.max_time_s();
  parameters.tolerance_samples = job.tolerance_samples();
  if (max_vertices > 0 && parameters.resolution > max_vertices)
    return ServiceStatus::field_error(StatusCode::ResourceExhausted, "resolution",
                                      "resolution " + std::to_string(parameters.resolution) +
                                          " is over this server's limit of " + std::to_string(max_vertices) + " vertices");
  if (check_mesh) {
    // What prepare_design checks before its remeshing, in the same words; the remeshing itself (seconds
    // of CGAL for a large target) runs once, on the worker.
    if (const std::vector<jobs::FieldProblem> problems = jobs::design_parameter_problems(parameters); !problems.empty())
      return bad_fields(problems);
    if (const std::string problem = material_problem(*material); !problem.empty())
      return ServiceStatus::bad_field("material", "material: " + problem);
    if (parameters.resolution > 0 && parameters.resolution < MIN_REMESH_RESOLUTION)
      return ServiceStatus::bad_field("resolution",
                                      "target_mesh: resolution must be 0 (never remesh) or at least 100 vertices, got " +
                                          std::to_string(parameters.resolution));
    TriMesh checked = mesh;
    if (Result<MeshCheckReport> report = validate_balloon_mesh(checked); !report)
      return ServiceStatus::bad_field("target_mesh", "target_mesh: target mesh: " + report.error());
    if (const std::string problem = jobs::design_size_problem(parameters, bounding_box_diagonal(checked.vertices));
        !problem.empty())
      return ServiceStatus::bad_field("target_mesh", "target_mesh: " + problem);
    if (const std::string problem = nozzle_problem(std::move(checked), parameters); !problem.empty())
      return ServiceStatus::bad_field("nozzle", problem);
  }
  decoded->target = std::move(mesh);
  decoded->material = std::move(*material);
  return ServiceStatus::success();
}

/// Prepares a decoded design (remeshing the target): the worker's part.
ServiceStatus prepare(DecodedDesign decoded, std::optional<jobs::DesignInput>* loaded) {
  Result<jobs::DesignInput> input = jobs::prepare_design(std::move(decoded.target), decoded.material, decoded.parameters);
  if (!input) {
    std::string message = input.error();
    if (message.rfind("mesh: ", 0) == 0) message = "target_" + message;
    return ServiceStatus::error(StatusCode::InvalidArgument, message);
  }
  *loaded = std::move(*input);
  return ServiceStatus::success();
}

/// One line for the job list; the vertex count is the target's as uploaded (remeshing comes later).
std::string design_summary(const DecodedDesign& design) {
  const jobs::DesignParameters& parameters = design.parameters;
  const DesignMethod method =
      parameters.method.empty() ? DesignOptions{}.method : *parse_design_method(parameters.method);
  std::string summary = "design " + std::to_string(design.target.vertex_count()) + " vertices, " +
                        (design.material.name.empty() ? material_spec(design.material) : design.material.name) + ", " +
                        format_number(parameters.thickness_mm) + " mm, " + design_method_name(method) + ", ";
  if (parameters.scale)
    summary += "scale " + format_number(*parameters.scale);
  else
    summary += "V/V0=" + format_number(parameters.volume_ratio ? *parameters.volume_ratio : DesignOptions{}.volume_ratio);
  return summary;
}

/// The checkpoint an interrupted run of this job stored, decoded; none when absent or unreadable (the
/// design then starts over, which is always correct).
std::optional<DesignCheckpoint> checkpoint_of(const RunContext& context) {
  if (!context.design_checkpoint) return std::nullopt;
  Result<TriMesh> rest = store::decode_mesh_blob(context.design_checkpoint->second);
  if (!rest) return std::nullopt;
  return DesignCheckpoint{rest->vertices, context.design_checkpoint->first};
}

class DesignKind final : public JobKind {
 public:
  const char* name() const override { return "design"; }
  v1::JobKind proto_kind() const override { return v1::JOB_KIND_DESIGN; }

  ServiceStatus check(const v1::JobSpec& spec, const CheckContext& context, CheckedJob* checked) const override {
    DecodedDesign decoded;
    ServiceStatus status = decode_design(spec.design(), context.caller.tenant, context.max_mesh_vertices, true,
                                         context.materials, &decoded);
    if (!status.ok()) return std::move(status).under("design.");
    checked->stored_spec = spec;
    if (names_stored_material(spec.design().material()))
      checked->stored_spec.mutable_design()->mutable_material()->set_spec(material_spec(decoded.material));
    checked->summary = design_summary(decoded);
    return ServiceStatus::success();
  }

  RunOutcome run(RunContext& context) const override {
    // The limit on vertices was applied at submit time; a job accepted then runs now even if the limit shrank.
    DecodedDesign decoded;
    ServiceStatus status = decode_design(context.spec.design(), context.record.owner, 0, false, context.materials, &decoded);
    if (!status.ok()) return RunOutcome::failed(status.message);
    std::optional<jobs::DesignInput> loaded;
    status = prepare(std::move(decoded), &loaded);
    if (!status.ok()) return RunOutcome::failed(status.message);
    const jobs::DesignInput& input = *loaded;
    context.set_connectivity(input.target.mesh.faces);
    jobs::RunControls controls;
    controls.cancel = &context.cancel;
    controls.progress = context.progress;
    controls.max_time_s = run_budget_s(context);
    const jobs::DesignOutcome outcome = jobs::run_design(input, controls, checkpoint_of(context));
    if (context.cancel.cancelled()) return RunOutcome::stopped();
    if (outcome.result.rest.vertex_count() == 0)
      return RunOutcome::failed("the design produced no rest shape: " + outcome.result.message);
    store::ResultRecord result;
    result.converged = outcome.result.converged;
    result.rest_mesh = store::encode_mesh_blob(outcome.result.rest);
    result.inflated_mesh = store::encode_mesh_blob(TriMesh{outcome.result.inflated, outcome.result.rest.faces});
    result.report = design_report(input, outcome).SerializeAsString();
    if (outcome.mold_mesh) result.mold_mesh = store::encode_mesh_blob(*outcome.mold_mesh);
    const std::string errors = jobs::design_error_summary(outcome.result);
    std::string message = (outcome.result.converged ? "completed: converged in " : "completed without converging in ") +
                          format_seconds(outcome.result.time_s) + " s, " + errors +
                          (outcome.result.converged ? std::string() : ": " + outcome.result.message);
    return RunOutcome::completed(std::move(result), std::move(message));
  }
};

}  // namespace

const JobKind& design_kind() {
  static const DesignKind kind;
  return kind;
}

}  // namespace balloon::service
