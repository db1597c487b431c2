#pragma once
/// One kind of job (simulate, design, fit_material): how its request is checked at submit, described,
/// run on a worker and returned as a result. Adding a kind touches one implementation file and the
/// list in job_kinds.cpp; the handler, the pool and the watch hub do not change.
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "balloon/v1/balloon.pb.h"
#include "jobs/field_problem.hpp"
#include "mesh/tri_mesh.hpp"
#include "progress.hpp"
#include "service/caller.hpp"
#include "service/material_handler.hpp"
#include "service/service_status.hpp"
#include "store/job_store.hpp"

namespace balloon::service {

/// What a kind may use to check a request at submit time (cheap work only: no remeshing, no solving).
struct CheckContext {
  const Caller& caller;
  MaterialHandler& materials;
  int max_mesh_vertices = 0;  ///< larger meshes are RESOURCE_EXHAUSTED; 0 = no limit (a job accepted earlier)
};

/// A request that passed the submit checks.
struct CheckedJob {
  balloon::v1::JobSpec stored_spec;  ///< what the store keeps (a stored material's name resolved to its SPEC)
  std::string summary;               ///< one human line
  /// The decoded, checked job, if the kind hands it to its run (same process: the run then neither parses
  /// nor checks the spec again). Only the kind that made it reads it.
  std::shared_ptr<const void> prepared = nullptr;
};

/// What a running job may use.
struct RunContext {
  const store::JobRecord& record;
  const balloon::v1::JobSpec& spec;
  const CancelToken& cancel;  ///< fires on cancel, time limit and shutdown
  ProgressCallback progress;  ///< publishes and checkpoints progress events
  /// Gives the watch hub the triangles the first intermediate mesh carries.
  std::function<void(const Faces&)> set_connectivity;
  MaterialHandler& materials;
  /// The job's last design checkpoint (iteration, rest shape as an encode_mesh_blob), if an earlier run of
  /// it stored one before it was interrupted.
  std::optional<std::pair<int, std::string>> design_checkpoint = std::nullopt;
  /// What check() prepared for this job at submit in this process (CheckedJob::prepared), or null.
  std::shared_ptr<const void> prepared = nullptr;
  /// When the job's time limit stops it (the cancel token fires then), if it has one.
  std::optional<std::chrono::steady_clock::time_point> deadline = std::nullopt;
};

/// How a run ended. The handler records it: one path for each outcome.
struct RunOutcome {
  enum class Kind { Completed, Failed, Stopped };
  Kind kind = Kind::Failed;
  store::ResultRecord result;  ///< Completed only
  std::string message;         ///< Completed: the one-line summary; Failed: the error

  static RunOutcome completed(store::ResultRecord result, std::string message) {
    return {Kind::Completed, std::move(result), std::move(message)};
  }
  static RunOutcome failed(std::string error) { return {Kind::Failed, {}, std::move(error)}; }
  /// The cancel token fired: the handler records why (cancel, time limit or shutdown).
  static RunOutcome stopped() { return {Kind::Stopped, {}, {}}; }
};

class JobKind {
 public:
  virtual ~JobKind() = default;
  /// The kind as stored ("simulate", "design", "fit_material").
  virtual const char* name() const = 0;
  virtual balloon::v1::JobKind proto_kind() const = 0;
  /// Decodes and checks `spec` within the limits; errors carry their status code.
  virtual ServiceStatus check(const balloon::v1::JobSpec& spec, const CheckContext& context,
                              CheckedJob* checked) const = 0;
  /// Runs the job to an outcome. May throw: the handler records any exception as a failure.
  virtual RunOutcome run(RunContext& context) const = 0;
  /// Fills `reply` from a stored result; meshes in `format` (checked writable by the caller), a design's
  /// mold in STL, and the typed report (fill_report).
  virtual ServiceStatus fill_result(const store::ResultRecord& stored, balloon::v1::MeshFormat format,
                                    balloon::v1::JobResult* reply, bool inflated_mesh_only = false) const;
  /// Sets the kind's report in `reply` from the stored one.
  ServiceStatus fill_report(const store::ResultRecord& stored, balloon::v1::JobResult* reply) const;
};

/// The kind a spec asks for; null when it names none.
const JobKind* job_kind_for(const balloon::v1::JobSpec& spec);
/// The kind with this stored name; null for an unknown name.
const JobKind* job_kind_named(const std::string& name);

/// Mesh format enum -> the extension core's mesh_io takes; empty for UNSPECIFIED or unknown values.
std::string mesh_format_extension(balloon::v1::MeshFormat format);
/// Reads an uploaded mesh (`field` names it in messages and is the error's field path, e.g. "rest_mesh")
/// within `max_vertices` (0: no limit): INVALID_ARGUMENT for an empty, unknown or unreadable upload,
/// RESOURCE_EXHAUSTED over the limit.
ServiceStatus read_uploaded_mesh(const balloon::v1::MeshFile& file, const std::string& field, int max_vertices,
                                 TriMesh* mesh);
/// INVALID_ARGUMENT with one field violation per problem (paths as the job layer names them, relative to
/// the job message); the message is the first problem's. `problems` is not empty.
ServiceStatus bad_fields(const std::vector<jobs::FieldProblem>& problems);
/// A run's own time budget (s) under its job's time limit, for RunControls::max_time_s: the time left
/// less a tenth of it (1 to 30 s) for the results and the report, so that the run stops itself and hands
/// back what it has (a design its best design, a simulation its last equilibrium, a curve its points so
/// far) instead of being cancelled at the limit and failed with nothing kept. 0 without a limit.
double run_budget_s(const RunContext& context);
/// "%g" of a number.
std::string format_number(double value);
/// A measured duration as people read it: 0.0123 -> "0.01", 5.76272 -> "5.76", 123.456 -> "123.5" (s).
std::string format_seconds(double seconds);
/// True when `reference` names a tenant's stored material (not a preset, not an inline SPEC): the job
/// then stores the SPEC as resolved at submit, so editing the material later does not change it.
bool names_stored_material(const balloon::v1::MaterialRef& reference);

}  // namespace balloon::service

namespace balloon::service {
/// The kinds (one file each: simulate_kind.cpp, design_kind.cpp, fit_material_kind.cpp, curve_kind.cpp).
const JobKind& simulate_kind();
const JobKind& design_kind();
const JobKind& fit_material_kind();
/// A simulate job with SimulateJob.curve (curve_kind.cpp).
const JobKind& curve_kind();
}  // namespace balloon::service
