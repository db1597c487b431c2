// The curve job kind: a simulate job with SimulateJob.curve, the whole pressure-volume curve in one
// continuation path (jobs/simulate_job run_curve); stores the rest mesh, the last converged equilibrium
// and the CurveReport (curve.csv and curve.svg are made from it by proto/contract).
#include "jobs/simulate_job.hpp"
#include "service/job_kind.hpp"
#include "service/job_reports.hpp"
#include "service/simulate_loading.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;

std::string curve_summary(const jobs::SimulateInput& input) {
  const jobs::CurveParameters& curve = *input.curve;
  const bool pressure = curve.control == InflationControl::Pressure;
  return "curve " + std::to_string(input.rest.vertex_count()) + " vertices, " +
         (input.material.name.empty() ? material_spec(input.material) : input.material.name) + ", " +
         format_number(input.thickness_mm) + " mm, " + std::to_string(curve.points) + " points over " +
         (pressure ? "p=" : "V/V0=") + format_number(curve.from) + ".." + format_number(curve.to) +
         (pressure ? " kPa" : "");
}

class CurveKind final : public JobKind {
 public:
  const char* name() const override { return "curve"; }
  v1::JobKind proto_kind() const override { return v1::JOB_KIND_CURVE; }

  ServiceStatus check(const v1::JobSpec& spec, const CheckContext& context, CheckedJob* checked) const override {
    std::optional<jobs::SimulateInput> input;
    if (ServiceStatus status = check_simulate_spec(spec, context, checked, &input); !status.ok()) return status;
    checked->summary = curve_summary(*input);
    return ServiceStatus::success();
  }

  RunOutcome run(RunContext& context) const override {
    std::optional<jobs::SimulateInput> loaded;
    const ServiceStatus status = load_simulate(context.spec.simulate(), context.record.owner, 0, context.materials, &loaded);
    if (!status.ok()) return RunOutcome::failed(status.message);
    const jobs::SimulateInput& input = *loaded;
    context.set_connectivity(input.rest.faces);
    jobs::RunControls controls;
    controls.cancel = &context.cancel;
    controls.progress = context.progress;
    controls.max_time_s = run_budget_s(context);
    const PressureVolumeCurve curve = jobs::run_curve(input, controls);
    if (context.cancel.cancelled()) return RunOutcome::stopped();
    store::ResultRecord result;
    result.converged = curve.converged;
    result.rest_mesh = store::encode_mesh_blob(input.rest);
    result.inflated_mesh = store::encode_mesh_blob(TriMesh{curve.last_shape, input.rest.faces});
    result.report = curve_report(input, curve).SerializeAsString();
    const int reached = curve.last_converged_point + 1;
    std::string message = curve.converged ? "completed: " + std::to_string(curve.points.size()) + " points in " +
                                                format_seconds(curve.time_s) + " s"
                                          : "completed with " + std::to_string(reached) + " of " +
                                                std::to_string(curve.points.size()) + " points: " + curve.message;
    return RunOutcome::completed(std::move(result), std::move(message));
  }
};

}  // namespace

const JobKind& curve_kind() {
  static const CurveKind kind;
  return kind;
}

}  // namespace balloon::service
