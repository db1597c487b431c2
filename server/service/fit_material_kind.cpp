// The fit_material job kind: fit rubber laws to measurements (jobs/fit_job); the report is the result and,
// with a name, the best fit is stored as the owner's material (with its provenance) before the job completes.
#include <algorithm>

#include "jobs/fit_job.hpp"
#include "service/job_kind.hpp"
#include "service/job_reports.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;

/// The name a measurement set goes by: its label, or "data[i]" when the client sent none.
std::string measurement_label(const v1::FitMaterialJob& job, int i) {
  return job.data(i).label().empty() ? "data[" + std::to_string(i) + "]" : job.data(i).label();
}

/// The proto measurement sets as the job layer's files.
std::vector<jobs::FitDataFile> fit_files(const v1::FitMaterialJob& job) {
  std::vector<jobs::FitDataFile> files;
  files.reserve(static_cast<size_t>(job.data_size()));
  for (int i = 0; i < job.data_size(); ++i) {
    const v1::MeasurementSet& set = job.data(i);
    jobs::FitDataFile file;
    file.label = measurement_label(job, i);
    file.csv_text = set.csv();
    file.test = set.test();
    file.radius_mm = set.radius_mm();
    file.thickness_mm = set.thickness_mm();
    files.push_back(std::move(file));
  }
  return files;
}

/// Checks a fit job (data, model, the name it stores under). Errors carry their status code and the
/// field at fault, relative to the FitMaterialJob ("data", "model", "name").
ServiceStatus check_fit(const v1::FitMaterialJob& job, std::optional<jobs::FitInput>* input) {
  if (job.data_size() == 0) return ServiceStatus::bad_field("data", "fit_material.data is empty");
  if (!job.name().empty()) {
    const std::string problem = material_name_problem(job.name());
    if (!problem.empty()) return ServiceStatus::bad_field("name", "fit_material.name: " + problem);
    const std::vector<std::string> presets = preset_names();
    if (std::find(presets.begin(), presets.end(), job.name()) != presets.end())
      return ServiceStatus::field_error(StatusCode::PermissionDenied, "name",
                                        "fit_material.name: '" + job.name() + "' is a preset and cannot be overwritten");
  }
  Result<jobs::FitInput> prepared = jobs::prepare_fit(fit_files(job), job.model());
  if (!prepared) {
    // prepare_fit checks the model before the data: with a known model, the data is at fault.
    const bool known_model = job.model() == "all" || parse_model_name(job.model());
    return ServiceStatus::bad_field(known_model ? "data" : "model", "fit_material: " + prepared.error());
  }
  *input = std::move(*prepared);
  return ServiceStatus::success();
}

std::string fit_summary(const v1::FitMaterialJob& job, const jobs::FitInput& input) {
  std::string summary = "fit_material " + job.model() + " to " + std::to_string(input.sets.size()) + " data set(s)";
  if (!job.name().empty()) summary += ", stored as " + job.name();
  return summary;
}

class FitMaterialKind final : public JobKind {
 public:
  const char* name() const override { return "fit_material"; }
  v1::JobKind proto_kind() const override { return v1::JOB_KIND_FIT_MATERIAL; }

  ServiceStatus check(const v1::JobSpec& spec, const CheckContext&, CheckedJob* checked) const override {
    std::optional<jobs::FitInput> input;
    ServiceStatus status = check_fit(spec.fit_material(), &input);
    if (!status.ok()) return std::move(status).under("fit_material.");
    checked->stored_spec = spec;
    checked->summary = fit_summary(spec.fit_material(), *input);
    return ServiceStatus::success();
  }

  RunOutcome run(RunContext& context) const override {
    const v1::FitMaterialJob& job = context.spec.fit_material();
    std::optional<jobs::FitInput> input;
    if (const ServiceStatus checked = check_fit(job, &input); !checked.ok()) return RunOutcome::failed(checked.message);
    // The fit checks the token between iterations: cancel, the time limit and shutdown stop it midway.
    Result<jobs::FitOutcome> outcome = jobs::run_fit(*input, &context.cancel);
    if (context.cancel.cancelled()) return RunOutcome::stopped();
    if (!outcome) return RunOutcome::failed(outcome.error());
    const FitResult& best = outcome->fits[static_cast<size_t>(jobs::best_fit_index(*outcome))];
    std::string stored_note;
    if (!job.name().empty()) {
      std::vector<std::string> labels;
      for (int i = 0; i < job.data_size(); ++i) labels.push_back(measurement_label(job, i));
      v1::PutMaterialRequest put;
      put.mutable_material()->set_name(job.name());
      put.mutable_material()->set_spec(material_spec(best.material));
      put.mutable_material()->set_description(jobs::fit_provenance(*input, best, labels));
      v1::Material stored_material;
      const ServiceStatus status = context.materials.put(Caller{context.record.owner}, put, &stored_material);
      if (!status.ok()) return RunOutcome::failed("storing material '" + job.name() + "': " + status.message);
      stored_note = ", stored as " + stored_material.name();
    }
    store::ResultRecord result;
    result.converged = true;
    for (const FitResult& fit : outcome->fits) result.converged = result.converged && fit.converged;
    result.report = fit_report(*input, *outcome).SerializeAsString();
    std::string message = "completed: best fit " + material_spec(best.material) + " in " +
                          format_seconds(outcome->time_s) + " s" + stored_note;
    return RunOutcome::completed(std::move(result), std::move(message));
  }

  // A fit has no meshes: the report is the whole result.
  ServiceStatus fill_result(const store::ResultRecord& stored, v1::MeshFormat, v1::JobResult* reply,
                            bool) const override {
    reply->set_kind(proto_kind());
    reply->set_converged(stored.converged);
    return fill_report(stored, reply);
  }
};

}  // namespace

const JobKind& fit_material_kind() {
  static const FitMaterialKind kind;
  return kind;
}

}  // namespace balloon::service
