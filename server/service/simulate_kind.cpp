// The simulate job kind: inflate a rest mesh (jobs/simulate_job) and store the rest and inflated meshes.
#include "jobs/simulate_job.hpp"
#include "mesh/mesh_io.hpp"
#include "service/job_kind.hpp"
#include "service/job_reports.hpp"
#include "service/simulate_loading.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {

namespace v1 = balloon::v1;

ServiceStatus load_simulate(const v1::SimulateJob& job, const std::string& tenant, int max_vertices,
                            MaterialHandler& materials, std::optional<jobs::SimulateInput>* loaded) {
  TriMesh mesh;
  if (ServiceStatus read = read_uploaded_mesh(job.rest_mesh(), "rest_mesh", max_vertices, &mesh); !read.ok())
    return read;
  Result<Material> material = materials.resolve(tenant, job.material());
  if (!material) return ServiceStatus::bad_field("material", "material: " + material.error());

  jobs::SimulateParameters parameters;
  parameters.thickness_mm = job.thickness_mm() == 0.0 ? jobs::DEFAULT_THICKNESS_MM : job.thickness_mm();
  parameters.size_mm = job.size_mm();
  if (job.control_case() == v1::SimulateJob::kPressureKpa) parameters.pressure_kpa = job.pressure_kpa();
  if (job.control_case() == v1::SimulateJob::kVolumeRatio) parameters.volume_ratio = job.volume_ratio();
  if (job.control_case() == v1::SimulateJob::kCurve) {
    jobs::CurveParameters curve;
    const bool pressure = job.curve().range_case() == v1::CurveSweep::kPressureRange;
    const v1::ValueRange& range = pressure ? job.curve().pressure_range() : job.curve().volume_ratio_range();
    curve.control = pressure ? InflationControl::Pressure : InflationControl::VolumeRatio;
    curve.from = range.from();
    curve.to = range.to();
    curve.points = job.curve().points();
    parameters.curve = curve;
  }
  // The parameters and the material are checked here first, each bad field by name (prepare_simulate
  // checks them again), so what prepare_simulate still refuses is the mesh.
  if (const std::vector<jobs::FieldProblem> problems = jobs::simulate_parameter_problems(parameters); !problems.empty())
    return bad_fields(problems);
  if (const std::string problem = material_problem(*material); !problem.empty())
    return ServiceStatus::bad_field("material", "material: " + problem);
  Result<jobs::SimulateInput> input = jobs::prepare_simulate(std::move(mesh), *material, parameters);
  if (!input) {
    // prepare_simulate prefixes mesh problems with "mesh: "; name the field the caller knows.
    std::string message = input.error();
    if (message.rfind("mesh: ", 0) == 0) message = "rest_" + message;
    return ServiceStatus::bad_field("rest_mesh", message);
  }
  *loaded = std::move(*input);
  return ServiceStatus::success();
}

ServiceStatus check_simulate_spec(const v1::JobSpec& spec, const CheckContext& context, CheckedJob* checked,
                                  std::optional<jobs::SimulateInput>* input) {
  ServiceStatus status =
      load_simulate(spec.simulate(), context.caller.tenant, context.max_mesh_vertices, context.materials, input);
  if (!status.ok()) return std::move(status).under("simulate.");
  checked->stored_spec = spec;
  if (names_stored_material(spec.simulate().material()))
    checked->stored_spec.mutable_simulate()->mutable_material()->set_spec(material_spec((*input)->material));
  return ServiceStatus::success();
}

namespace {

std::string simulate_summary(const jobs::SimulateInput& input) {
  std::string summary = "simulate " + std::to_string(input.rest.vertex_count()) + " vertices, " +
                        (input.material.name.empty() ? material_spec(input.material) : input.material.name) + ", " +
                        format_number(input.thickness_mm) + " mm, ";
  if (input.control == InflationControl::Pressure)
    summary += "p=" + format_number(input.pressure_kpa) + " kPa";
  else
    summary += "V/V0=" + format_number(input.volume_ratio);
  return summary;
}

class SimulateKind final : public JobKind {
 public:
  const char* name() const override { return "simulate"; }
  v1::JobKind proto_kind() const override { return v1::JOB_KIND_SIMULATE; }

  ServiceStatus check(const v1::JobSpec& spec, const CheckContext& context, CheckedJob* checked) const override {
    std::optional<jobs::SimulateInput> input;
    if (ServiceStatus status = check_simulate_spec(spec, context, checked, &input); !status.ok()) return status;
    checked->summary = simulate_summary(*input);
    checked->prepared = std::make_shared<const jobs::SimulateInput>(std::move(*input));
    return ServiceStatus::success();
  }

  RunOutcome run(RunContext& context) const override {
    // Checked at submit in this process: as prepared then. Otherwise (a restart, a recovered job) from the
    // stored spec; the limit on vertices was applied at submit, so a job accepted then runs now even if the
    // limit shrank.
    auto prepared = std::static_pointer_cast<const jobs::SimulateInput>(context.prepared);
    if (!prepared) {
      std::optional<jobs::SimulateInput> loaded;
      const ServiceStatus status =
          load_simulate(context.spec.simulate(), context.record.owner, 0, context.materials, &loaded);
      if (!status.ok()) return RunOutcome::failed(status.message);
      prepared = std::make_shared<const jobs::SimulateInput>(std::move(*loaded));
    }
    const jobs::SimulateInput& input = *prepared;
    context.set_connectivity(input.rest.faces);
    jobs::RunControls controls;
    controls.cancel = &context.cancel;
    controls.progress = context.progress;
    controls.max_time_s = run_budget_s(context);
    const jobs::SimulateOutcome outcome = jobs::run_simulate(input, controls);
    if (context.cancel.cancelled()) return RunOutcome::stopped();
    store::ResultRecord result;
    result.converged = outcome.result.converged;
    result.rest_mesh = store::encode_mesh_blob(input.rest);
    result.inflated_mesh = store::encode_mesh_blob(TriMesh{outcome.result.deformed, input.rest.faces});
    result.report = simulate_report(input, outcome.result).SerializeAsString();
    std::string message = outcome.result.converged
                              ? "completed: converged in " + format_seconds(outcome.result.time_s) + " s"
                              : "completed without converging: " + outcome.result.message;
    return RunOutcome::completed(std::move(result), std::move(message));
  }
};

}  // namespace

const JobKind& simulate_kind() {
  static const SimulateKind kind;
  return kind;
}

}  // namespace balloon::service
