#include "service/job_handler.hpp"
#include "service/shard_name.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "jobs/design_job.hpp"
#include "jobs/fit_job.hpp"
#include "jobs/simulate_job.hpp"
#include "mesh/mesh_io.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;
using store::JobState;

constexpr const char* KIND_SIMULATE = "simulate";
constexpr const char* KIND_DESIGN = "design";
constexpr const char* KIND_FIT_MATERIAL = "fit_material";
constexpr int MAX_PAGE_SIZE = 1000;
constexpr int DEFAULT_PAGE_SIZE = 100;
constexpr double SHAPE_CHECKPOINT_INTERVAL_S = 1.0;  // stored shapes are big: at most one a second per job

v1::JobState to_proto(JobState state) {
  switch (state) {
    case JobState::Queued: return v1::JOB_STATE_QUEUED;
    case JobState::Running: return v1::JOB_STATE_RUNNING;
    case JobState::Completed: return v1::JOB_STATE_COMPLETED;
    case JobState::Failed: return v1::JOB_STATE_FAILED;
    case JobState::Cancelled: return v1::JOB_STATE_CANCELLED;
  }
  return v1::JOB_STATE_UNSPECIFIED;
}

v1::JobKind kind_to_proto(const std::string& kind) {
  if (kind == KIND_SIMULATE) return v1::JOB_KIND_SIMULATE;
  if (kind == KIND_DESIGN) return v1::JOB_KIND_DESIGN;
  if (kind == KIND_FIT_MATERIAL) return v1::JOB_KIND_FIT_MATERIAL;
  return v1::JOB_KIND_UNSPECIFIED;
}

std::int64_t now_ms() { return store::now_ms(); }

std::string format_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

/// A decoded, checked simulate job, or an error with the status code it deserves.
struct LoadedSimulate {
  std::optional<jobs::SimulateInput> input;
  StatusCode code = StatusCode::Ok;
  std::string error;
};

void fill_progress(const store::ProgressRecord& record, v1::Progress* progress) {
  progress->set_phase(record.phase);
  progress->set_iteration(record.iteration);
  progress->set_elapsed_s(record.elapsed_s);
  progress->set_residual_norm(record.residual_norm);
  progress->set_pressure_kpa(record.pressure_kpa);
  progress->set_avg_error_mm(record.avg_error_mm);
  progress->set_max_error_mm(record.max_error_mm);
}

v1::JobEvent state_event(const std::string& job_id, v1::JobState state, const std::string& message) {
  v1::JobEvent event;
  event.set_job_id(job_id);
  event.set_state(state);
  event.set_message(message);
  event.set_time_ms(now_ms());
  return event;
}

}  // namespace

/// Mesh format enum -> the extension core's mesh_io takes; empty for UNSPECIFIED or unknown values.
static std::string mesh_format_extension(v1::MeshFormat format) {
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

static LoadedSimulate load_simulate(const v1::SimulateJob& job, const std::string& tenant, int max_vertices,
                                    MaterialHandler& materials) {
  LoadedSimulate loaded;
  auto failure = [&](StatusCode code, std::string message) {
    loaded.code = code;
    loaded.error = std::move(message);
    return loaded;
  };
  if (job.rest_mesh().data().empty()) return failure(StatusCode::InvalidArgument, "rest_mesh is empty");
  const std::string extension = mesh_format_extension(job.rest_mesh().format());
  if (extension.empty())
    return failure(StatusCode::InvalidArgument, "rest_mesh.format is missing or unknown (OBJ, STL, PLY, OFF, GLTF, GLB)");
  Result<TriMesh> mesh = read_mesh_from_memory(job.rest_mesh().data(), extension, upload_limits(max_vertices));
  if (!mesh) {
    return failure(is_over_limit_error(mesh.error()) ? StatusCode::ResourceExhausted : StatusCode::InvalidArgument,
                   "rest_mesh: " + mesh.error());
  }
  if (max_vertices > 0 && mesh->vertex_count() > max_vertices)
    return failure(StatusCode::ResourceExhausted, "rest_mesh has " + std::to_string(mesh->vertex_count()) +
                                                      " vertices, over this server's limit of " +
                                                      std::to_string(max_vertices));
  Result<Material> material = materials.resolve(tenant, job.material());
  if (!material) return failure(StatusCode::InvalidArgument, "material: " + material.error());

  jobs::SimulateParameters parameters;
  parameters.thickness_mm = job.thickness_mm() == 0.0 ? jobs::DEFAULT_THICKNESS_MM : job.thickness_mm();
  if (job.control_case() == v1::SimulateJob::kPressureKpa) parameters.pressure_kpa = job.pressure_kpa();
  if (job.control_case() == v1::SimulateJob::kVolumeRatio) parameters.volume_ratio = job.volume_ratio();
  Result<jobs::SimulateInput> input = jobs::prepare_simulate(std::move(*mesh), *material, parameters);
  if (!input) {
    // prepare_simulate prefixes mesh problems with "mesh: "; name the field the caller knows.
    std::string message = input.error();
    if (message.rfind("mesh: ", 0) == 0) message = "rest_" + message;
    return failure(StatusCode::InvalidArgument, message);
  }
  loaded.input = std::move(*input);
  return loaded;
}

/// A decoded, checked design job, or an error with the status code it deserves.
struct LoadedDesign {
  std::optional<jobs::DesignInput> input;
  StatusCode code = StatusCode::Ok;
  std::string error;
};

static LoadedDesign load_design(const v1::DesignJob& job, const std::string& tenant, int max_vertices,
                                MaterialHandler& materials) {
  LoadedDesign loaded;
  auto failure = [&](StatusCode code, std::string message) {
    loaded.code = code;
    loaded.error = std::move(message);
    return loaded;
  };
  if (job.target_mesh().data().empty()) return failure(StatusCode::InvalidArgument, "target_mesh is empty");
  const std::string extension = mesh_format_extension(job.target_mesh().format());
  if (extension.empty())
    return failure(StatusCode::InvalidArgument, "target_mesh.format is missing or unknown (OBJ, STL, PLY, OFF, GLTF, GLB)");
  Result<TriMesh> mesh = read_mesh_from_memory(job.target_mesh().data(), extension, upload_limits(max_vertices));
  if (!mesh) {
    return failure(is_over_limit_error(mesh.error()) ? StatusCode::ResourceExhausted : StatusCode::InvalidArgument,
                   "target_mesh: " + mesh.error());
  }
  if (max_vertices > 0 && mesh->vertex_count() > max_vertices)
    return failure(StatusCode::ResourceExhausted, "target_mesh has " + std::to_string(mesh->vertex_count()) +
                                                      " vertices, over this server's limit of " +
                                                      std::to_string(max_vertices));
  Result<Material> material = materials.resolve(tenant, job.material());
  if (!material) return failure(StatusCode::InvalidArgument, "material: " + material.error());

  jobs::DesignParameters parameters;
  parameters.thickness_mm = job.thickness_mm() == 0.0 ? jobs::DEFAULT_THICKNESS_MM : job.thickness_mm();
  parameters.size_mm = job.size_mm();
  // On the wire 0 means the default and < 0 "never remesh" (proto3 has no unset ints); here 0 never remeshes.
  parameters.resolution = job.resolution() == 0 ? jobs::DEFAULT_DESIGN_RESOLUTION : std::max(0, job.resolution());
  if (job.inflation_case() == v1::DesignJob::kScale) parameters.scale = job.scale();
  if (job.inflation_case() == v1::DesignJob::kVolumeRatio) parameters.volume_ratio = job.volume_ratio();
  parameters.method = job.method();
  parameters.nozzle = job.nozzle();
  parameters.max_time_s = job.max_time_s();
  parameters.tolerance_samples = job.tolerance_samples();
  if (max_vertices > 0 && parameters.resolution > max_vertices)
    return failure(StatusCode::ResourceExhausted, "resolution " + std::to_string(parameters.resolution) +
                                                      " is over this server's limit of " +
                                                      std::to_string(max_vertices) + " vertices");
  Result<jobs::DesignInput> input = jobs::prepare_design(std::move(*mesh), *material, parameters);
  if (!input) {
    std::string message = input.error();
    if (message.rfind("mesh: ", 0) == 0) message = "target_" + message;
    return failure(StatusCode::InvalidArgument, message);
  }
  loaded.input = std::move(*input);
  return loaded;
}

/// The name a measurement set goes by: its label, or "data[i]" when the client sent none.
static std::string measurement_label(const v1::FitMaterialJob& job, int i) {
  return job.data(i).label().empty() ? "data[" + std::to_string(i) + "]" : job.data(i).label();
}

/// The proto measurement sets as the job layer's files.
static std::vector<jobs::FitDataFile> fit_files(const v1::FitMaterialJob& job) {
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

/// Checks a fit job (data, model, the name it stores under). Errors carry their status code.
static ServiceStatus check_fit(const v1::FitMaterialJob& job, std::optional<jobs::FitInput>* input) {
  if (job.data_size() == 0) return ServiceStatus::error(StatusCode::InvalidArgument, "fit_material.data is empty");
  if (!job.name().empty()) {
    const std::string problem = material_name_problem(job.name());
    if (!problem.empty()) return ServiceStatus::error(StatusCode::InvalidArgument, "fit_material.name: " + problem);
    const std::vector<std::string> presets = preset_names();
    if (std::find(presets.begin(), presets.end(), job.name()) != presets.end())
      return ServiceStatus::error(StatusCode::PermissionDenied,
                                  "fit_material.name: '" + job.name() + "' is a preset and cannot be overwritten");
  }
  Result<jobs::FitInput> prepared = jobs::prepare_fit(fit_files(job), job.model());
  if (!prepared) return ServiceStatus::error(StatusCode::InvalidArgument, "fit_material: " + prepared.error());
  *input = std::move(*prepared);
  return ServiceStatus::success();
}

static std::string fit_summary(const v1::FitMaterialJob& job, const jobs::FitInput& input) {
  std::string summary = "fit_material " + job.model() + " to " + std::to_string(input.sets.size()) + " data set(s)";
  if (!job.name().empty()) summary += ", stored as " + job.name();
  return summary;
}

static std::string design_summary(const jobs::DesignInput& input) {
  std::string summary = "design " + std::to_string(input.target.mesh.vertex_count()) + " vertices, " +
                        (input.material.name.empty() ? material_spec(input.material) : input.material.name) + ", " +
                        format_number(input.parameters.thickness_mm) + " mm, " + design_method_name(input.method) + ", ";
  if (input.parameters.scale)
    summary += "scale " + format_number(*input.parameters.scale);
  else
    summary += "V/V0=" + format_number(input.parameters.volume_ratio ? *input.parameters.volume_ratio
                                                                     : DesignOptions{}.volume_ratio);
  return summary;
}

static std::string simulate_summary(const jobs::SimulateInput& input) {
  std::string summary = "simulate " + std::to_string(input.rest.vertex_count()) + " vertices, " +
                        (input.material.name.empty() ? material_spec(input.material) : input.material.name) + ", " +
                        format_number(input.thickness_mm) + " mm, ";
  if (input.control == InflationControl::Pressure)
    summary += "p=" + format_number(input.pressure_kpa) + " kPa";
  else
    summary += "V/V0=" + format_number(input.volume_ratio);
  return summary;
}


JobHandler::JobHandler(const ServiceOptions& options, store::Store& store, MaterialHandler& materials)
    : m_options(options), m_store(store), m_jobs(store), m_materials(materials),
      m_queue(static_cast<std::size_t>(std::max(1, options.max_queue))) {
  std::random_device device;
  m_id_state = (static_cast<std::uint64_t>(device()) << 32) ^ device() ^
               static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  if (m_options.workers <= 0) m_options.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (m_options.progress_mesh_every == 0) m_options.progress_mesh_every = 1;
}

JobHandler::~JobHandler() { shutdown(); }

void JobHandler::log(const std::string& line) const {
  if (m_options.log) m_options.log(line);
}

bool JobHandler::acquire_store_lock() {
  // Unfinished jobs in the store belong to a process that died, unless another live process uses the
  // same file. An exclusive lock on a side file tells which; afterwards every process holds it shared.
  const std::string& path = m_store.path();
  if (path.empty() || path == ":memory:") return true;
  m_lock_fd = ::open((path + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (m_lock_fd < 0) return false;
  const bool sole_user = ::flock(m_lock_fd, LOCK_EX | LOCK_NB) == 0;
  if (!sole_user) {
    ::flock(m_lock_fd, LOCK_SH);
  }
  return sole_user;
}

int JobHandler::start() {
  if (m_started) return 0;
  m_started = true;
  int recovered = 0;
  if (!m_options.run_jobs) return 0;  // a client-only process: leave every job as the store has it
  const bool sole_user = acquire_store_lock();
  if (m_options.recover && sole_user) {
    for (const store::JobRecord& job : m_jobs.recover_unfinished()) {
      m_queue.push_recovered(job.row_id, job.priority);
      ++recovered;
    }
    if (recovered > 0) log("recovered " + std::to_string(recovered) + " unfinished job(s) from " + m_store.path());
  } else if (!sole_user) {
    log("another process uses " + m_store.path() + "; not recovering its unfinished jobs");
  }
  if (m_lock_fd >= 0 && sole_user) ::flock(m_lock_fd, LOCK_SH);  // let other processes share the store now
  for (int i = 0; i < m_options.workers; ++i) m_workers.emplace_back([this] { worker_loop(); });
  m_watchdog = std::thread([this] { watchdog_loop(); });
  return recovered;
}

std::string JobHandler::new_job_id() {
  std::lock_guard lock(m_id_mutex);
  // splitmix64: distinct ids from a random seed, no collisions within a process.
  std::uint64_t z = (m_id_state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  char buffer[24];
  std::snprintf(buffer, sizeof(buffer), "j-%016llx", static_cast<unsigned long long>(z));
  return shard_job_id(m_options.shard_name, buffer);
}

ServiceStatus JobHandler::submit(const Caller& caller, const v1::SubmitJobRequest& request,
                                 v1::SubmitJobResponse* reply) {
  if (m_stopping) return ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down");
  const v1::JobSpec& spec = request.spec();
  switch (spec.kind_case()) {
    case v1::JobSpec::kSimulate: break;
    case v1::JobSpec::kDesign: break;
    case v1::JobSpec::kFitMaterial: break;
    case v1::JobSpec::KIND_NOT_SET:
      return ServiceStatus::error(StatusCode::InvalidArgument, "spec names no job (simulate, design or fit_material)");
  }
  if (spec.priority() < -100 || spec.priority() > 100)
    return ServiceStatus::error(StatusCode::InvalidArgument, "priority must be within -100..100");
  if (spec.priority() > 0 && !caller.may_raise_priority)
    return ServiceStatus::error(StatusCode::PermissionDenied,
                                "priority above 0 is only for tenants marked 'raise-priority' in the token file");
  if (!std::isfinite(spec.time_limit_s()) || spec.time_limit_s() < 0.0)
    return ServiceStatus::error(StatusCode::InvalidArgument, "time_limit_s must be a finite number >= 0 (s)");

  // Store the material as resolved now: a stored material edited later must not change a queued job.
  v1::JobSpec stored = spec;
  const std::vector<std::string> presets = preset_names();
  const auto is_stored_name = [&](const v1::MaterialRef& ref) {
    return ref.kind_case() == v1::MaterialRef::kName &&
           std::find(presets.begin(), presets.end(), ref.name()) == presets.end();
  };
  std::string kind, summary;
  if (spec.kind_case() == v1::JobSpec::kDesign) {
    LoadedDesign loaded = load_design(spec.design(), caller.tenant, m_options.max_mesh_vertices, m_materials);
    if (!loaded.input) return ServiceStatus::error(loaded.code, loaded.error);
    if (is_stored_name(spec.design().material()))
      stored.mutable_design()->mutable_material()->set_spec(material_spec(loaded.input->material));
    kind = KIND_DESIGN;
    summary = design_summary(*loaded.input);
  } else if (spec.kind_case() == v1::JobSpec::kFitMaterial) {
    std::optional<jobs::FitInput> input;
    const ServiceStatus checked = check_fit(spec.fit_material(), &input);
    if (!checked.ok()) return checked;
    kind = KIND_FIT_MATERIAL;
    summary = fit_summary(spec.fit_material(), *input);
  } else {
    LoadedSimulate loaded = load_simulate(spec.simulate(), caller.tenant, m_options.max_mesh_vertices, m_materials);
    if (!loaded.input) return ServiceStatus::error(loaded.code, loaded.error);
    if (is_stored_name(spec.simulate().material()))
      stored.mutable_simulate()->mutable_material()->set_spec(material_spec(loaded.input->material));
    kind = KIND_SIMULATE;
    summary = simulate_summary(*loaded.input);
  }

  if (!m_queue.reserve())
    return ServiceStatus::error(StatusCode::ResourceExhausted,
                                "the queue is full (" + std::to_string(m_queue.capacity()) + " jobs waiting); retry later");
  store::JobRecord record;
  record.job_id = new_job_id();
  record.owner = caller.tenant;
  record.kind = kind;
  record.state = JobState::Queued;
  record.priority = spec.priority();
  record.summary = summary;
  record.created_ms = now_ms();
  if (!stored.SerializeToString(&record.spec)) {
    m_queue.release_reservation();
    return ServiceStatus::error(StatusCode::Internal, "could not serialize the job spec");
  }
  try {
    m_jobs.insert(record);
  } catch (...) {
    m_queue.release_reservation();
    throw;
  }
  m_queue.push_reserved(record.row_id, record.priority);
  log("job " + record.job_id + " submitted by " + caller.tenant + ": " + record.summary);
  fill_job(record, reply->mutable_job());
  return ServiceStatus::success();
}

std::optional<store::JobRecord> JobHandler::find_owned(const Caller& caller, const std::string& job_id) {
  std::optional<store::JobRecord> record = m_jobs.find(job_id);
  // Another tenant's job looks exactly like a missing one: ids are not a side channel.
  if (!record || record->owner != caller.tenant) return std::nullopt;
  return record;
}

void JobHandler::fill_job(const store::JobRecord& record, v1::Job* job) const {
  job->set_id(record.job_id);
  job->set_kind(kind_to_proto(record.kind));
  job->set_state(to_proto(record.state));
  job->set_priority(record.priority);
  job->set_error(record.error);
  job->set_converged(record.converged);
  job->set_summary(record.summary);
  job->set_created_ms(record.created_ms);
  job->set_started_ms(record.started_ms);
  job->set_finished_ms(record.finished_ms);
  job->set_attempts(record.attempts);
  if (record.last_progress) fill_progress(*record.last_progress, job->mutable_last_progress());
  if (record.state == JobState::Queued) job->set_queue_position(std::max(0, m_queue.position(record.row_id)));
}

ServiceStatus JobHandler::get(const Caller& caller, const v1::GetJobRequest& request, v1::Job* reply) {
  const auto record = find_owned(caller, request.job_id());
  if (!record) return ServiceStatus::error(StatusCode::NotFound, "no job '" + request.job_id() + "'");
  fill_job(*record, reply);
  return ServiceStatus::success();
}

ServiceStatus JobHandler::list(const Caller& caller, const v1::ListJobsRequest& request, v1::ListJobsResponse* reply) {
  int page_size = request.page_size() == 0 ? DEFAULT_PAGE_SIZE : request.page_size();
  if (page_size < 0 || page_size > MAX_PAGE_SIZE)
    return ServiceStatus::error(StatusCode::InvalidArgument, "page_size must be within 1..1000");
  std::int64_t before_row = 0;
  if (!request.page_token().empty()) {
    char* end = nullptr;
    before_row = std::strtoll(request.page_token().c_str(), &end, 10);
    if (*end != '\0' || before_row <= 0)
      return ServiceStatus::error(StatusCode::InvalidArgument, "page_token is not one this server gave out");
  }
  std::optional<JobState> state;
  switch (request.state()) {
    case v1::JOB_STATE_UNSPECIFIED: break;
    case v1::JOB_STATE_QUEUED: state = JobState::Queued; break;
    case v1::JOB_STATE_RUNNING: state = JobState::Running; break;
    case v1::JOB_STATE_COMPLETED: state = JobState::Completed; break;
    case v1::JOB_STATE_FAILED: state = JobState::Failed; break;
    case v1::JOB_STATE_CANCELLED: state = JobState::Cancelled; break;
    default: return ServiceStatus::error(StatusCode::InvalidArgument, "unknown state filter");
  }
  const store::JobPage page = m_jobs.list(caller.tenant, state, before_row, page_size);
  for (const store::JobRecord& record : page.jobs) fill_job(record, reply->add_jobs());
  if (page.next_before_row > 0) reply->set_next_page_token(std::to_string(page.next_before_row));
  return ServiceStatus::success();
}

ServiceStatus JobHandler::cancel(const Caller& caller, const v1::CancelJobRequest& request, v1::Job* reply) {
  auto record = find_owned(caller, request.job_id());
  if (!record) return ServiceStatus::error(StatusCode::NotFound, "no job '" + request.job_id() + "'");
  if (!store::is_terminal(record->state)) {
    m_queue.remove(record->row_id);
    const std::string reason = "cancelled by its owner";
    if (m_jobs.mark_cancelled(record->row_id, reason)) {
      // A running job stops at its next iteration; its state is final already.
      {
        std::lock_guard lock(m_active_mutex);
        if (const auto it = m_active.find(record->row_id); it != m_active.end()) {
          int expected = static_cast<int>(StopReason::None);
          it->second->stop_reason.compare_exchange_strong(expected, static_cast<int>(StopReason::Cancelled));
          it->second->token.cancel();
        }
      }
      log("job " + record->job_id + " cancelled");
      close_watchers(record->job_id, state_event(record->job_id, v1::JOB_STATE_CANCELLED, reason));
    }
    record = m_jobs.find(request.job_id());
  }
  fill_job(*record, reply);
  return ServiceStatus::success();
}

ServiceStatus JobHandler::watch(const Caller& caller, const v1::WatchJobRequest& request,
                                std::shared_ptr<WatchChannel>* channel) {
  if (m_stopping) return ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down");
  if (!find_owned(caller, request.job_id()))
    return ServiceStatus::error(StatusCode::NotFound, "no job '" + request.job_id() + "'");
  auto opened = std::make_shared<WatchChannel>();
  // Subscribe and take the snapshot under the watcher lock: publishers wait, so the snapshot comes first.
  std::lock_guard lock(m_watch_mutex);
  const auto record = m_jobs.find(request.job_id());
  if (!record) return ServiceStatus::error(StatusCode::NotFound, "no job '" + request.job_id() + "'");
  v1::JobEvent snapshot = state_event(record->job_id, to_proto(record->state), "");
  if (record->last_progress) fill_progress(*record->last_progress, snapshot.mutable_progress());
  snapshot.set_converged(record->converged);
  if (store::is_terminal(record->state)) {
    snapshot.set_message(record->error.empty() ? std::string("finished") : record->error);
    opened->close(std::move(snapshot), ServiceStatus::success());
  } else {
    snapshot.set_message(record->state == JobState::Queued ? "queued" : "running");
    opened->push(std::move(snapshot), nullptr);
    m_watchers.emplace(record->job_id, opened);
  }
  *channel = std::move(opened);
  return ServiceStatus::success();
}

void JobHandler::unwatch(const std::shared_ptr<WatchChannel>& channel) {
  std::lock_guard lock(m_watch_mutex);
  for (auto it = m_watchers.begin(); it != m_watchers.end();) {
    if (it->second == channel)
      it = m_watchers.erase(it);
    else
      ++it;
  }
}

void JobHandler::publish(const std::string& job_id, v1::JobEvent event) {
  std::vector<std::shared_ptr<WatchChannel>> channels;
  std::shared_ptr<const std::vector<std::uint32_t>> triangles;
  {
    std::lock_guard lock(m_watch_mutex);
    const auto range = m_watchers.equal_range(job_id);
    for (auto it = range.first; it != range.second; ++it) channels.push_back(it->second);
    if (const auto it = m_connectivity.find(job_id); it != m_connectivity.end()) triangles = it->second;
  }
  for (const auto& channel : channels) channel->push(event, triangles);
}

void JobHandler::close_watchers(const std::string& job_id, v1::JobEvent last_event) {
  std::vector<std::shared_ptr<WatchChannel>> channels;
  {
    std::lock_guard lock(m_watch_mutex);
    const auto range = m_watchers.equal_range(job_id);
    for (auto it = range.first; it != range.second; ++it) channels.push_back(it->second);
    m_watchers.erase(range.first, range.second);
    m_connectivity.erase(job_id);
  }
  for (const auto& channel : channels) channel->close(last_event, ServiceStatus::success());
}

ServiceStatus JobHandler::result(const Caller& caller, const v1::GetResultRequest& request, v1::JobResult* reply) {
  const auto record = find_owned(caller, request.job_id());
  if (!record) return ServiceStatus::error(StatusCode::NotFound, "no job '" + request.job_id() + "'");
  if (record->state != JobState::Completed) {
    std::string why = "job " + record->job_id + " is " + store::to_string(record->state);
    if (!record->error.empty()) why += " (" + record->error + ")";
    return ServiceStatus::error(StatusCode::FailedPrecondition, why + "; it has no result");
  }
  const v1::MeshFormat format = request.format() == v1::MESH_FORMAT_UNSPECIFIED ? v1::MESH_FORMAT_OBJ : request.format();
  const std::string extension = mesh_format_extension(format);
  if (extension.empty() || !is_writable_mesh_format(extension))
    return ServiceStatus::error(StatusCode::InvalidArgument, "meshes can be returned as OBJ, STL or PLY only");
  const auto stored = m_jobs.result(record->row_id);
  if (!stored) return ServiceStatus::error(StatusCode::Internal, "job " + record->job_id + " has lost its result");
  if (record->kind == KIND_FIT_MATERIAL) {
    // A fit has no meshes: the report is the whole result.
    reply->set_job_id(record->job_id);
    reply->set_kind(kind_to_proto(record->kind));
    reply->set_converged(stored->converged);
    reply->set_report_json(stored->report_json);
    return ServiceStatus::success();
  }
  const Result<TriMesh> rest = store::decode_mesh_blob(stored->rest_mesh);
  const Result<TriMesh> inflated = store::decode_mesh_blob(stored->inflated_mesh);
  if (!rest || !inflated) return ServiceStatus::error(StatusCode::Internal, "stored meshes are unreadable");
  reply->set_job_id(record->job_id);
  reply->set_kind(kind_to_proto(record->kind));
  reply->set_converged(stored->converged);
  reply->mutable_rest_mesh()->set_format(format);
  reply->mutable_rest_mesh()->set_data(write_mesh_to_memory(*rest, extension));
  reply->mutable_inflated_mesh()->set_format(format);
  reply->mutable_inflated_mesh()->set_data(write_mesh_to_memory(*inflated, extension));
  reply->set_report_json(stored->report_json);
  return ServiceStatus::success();
}

void JobHandler::worker_loop() {
  while (const std::optional<std::int64_t> row = m_queue.pop()) {
    try {
      run_job(*row);
    } catch (const std::exception& error) {
      // A job must never take its worker down with it.
      log(std::string("worker: unexpected error: ") + error.what());
    }
  }
}

void JobHandler::watchdog_loop() {
  std::unique_lock lock(m_watchdog_mutex);
  while (!m_stopping) {
    m_watchdog_wake.wait_for(lock, std::chrono::milliseconds(50));
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard active_lock(m_active_mutex);
    for (auto& [row, active] : m_active) {
      const double elapsed = std::chrono::duration<double>(now - active->started).count();
      if (active->time_limit_s > 0.0 && elapsed > active->time_limit_s) {
        int expected = static_cast<int>(StopReason::None);
        if (active->stop_reason.compare_exchange_strong(expected, static_cast<int>(StopReason::TimeLimit)))
          active->token.cancel();
      }
    }
  }
}

void JobHandler::run_job(std::int64_t row_id) {
  std::optional<store::JobRecord> record = m_jobs.find_row(row_id);
  if (!record || record->state != JobState::Queued) return;
  if (!m_jobs.mark_running(row_id)) return;  // cancelled between pop and start
  record->state = JobState::Running;
  record->attempts += 1;

  auto active = std::make_shared<ActiveJob>();
  active->job_id = record->job_id;
  active->started = std::chrono::steady_clock::now();
  v1::JobSpec spec;
  const bool spec_ok = spec.ParseFromString(record->spec);
  active->time_limit_s = spec.time_limit_s() > 0.0 ? std::min(spec.time_limit_s(), m_options.job_time_limit_s)
                                                   : m_options.job_time_limit_s;
  {
    std::lock_guard lock(m_active_mutex);
    m_active[row_id] = active;
    // A shutdown that began before we registered would miss this job: stop it ourselves.
    if (m_stopping) {
      active->stop_reason = static_cast<int>(StopReason::Shutdown);
      active->token.cancel();
    }
  }
  log("job " + record->job_id + " started (attempt " + std::to_string(record->attempts) + ")");
  publish(record->job_id, state_event(record->job_id, v1::JOB_STATE_RUNNING,
                                      "started (attempt " + std::to_string(record->attempts) + ")"));
  try {
    if (spec_ok && spec.kind_case() == v1::JobSpec::kSimulate) {
      run_simulate_job(*record, spec, *active);
    } else if (spec_ok && spec.kind_case() == v1::JobSpec::kDesign) {
      run_design_job(*record, spec, *active);
    } else if (spec_ok && spec.kind_case() == v1::JobSpec::kFitMaterial) {
      run_fit_job(*record, spec, *active);
    } else {
      const std::string error = spec_ok ? "this server cannot run this kind of job" : "the stored job spec is unreadable";
      m_jobs.mark_failed(row_id, error);
      close_watchers(record->job_id, state_event(record->job_id, v1::JOB_STATE_FAILED, error));
    }
  } catch (const std::exception& error) {
    const std::string message = std::string("internal error: ") + error.what();
    m_jobs.mark_failed(row_id, message);
    log("job " + record->job_id + " failed: " + message);
    close_watchers(record->job_id, state_event(record->job_id, v1::JOB_STATE_FAILED, message));
  }
  std::lock_guard lock(m_active_mutex);
  m_active.erase(row_id);
}

void JobHandler::run_simulate_job(const store::JobRecord& record, const v1::JobSpec& spec, ActiveJob& active) {
  // The limit on vertices was applied at submit time; a job accepted then runs now even if the limit shrank.
  LoadedSimulate loaded = load_simulate(spec.simulate(), record.owner, 0, m_materials);
  if (!loaded.input) {
    m_jobs.mark_failed(record.row_id, loaded.error);
    log("job " + record.job_id + " failed: " + loaded.error);
    close_watchers(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, loaded.error));
    return;
  }
  const jobs::SimulateInput& input = *loaded.input;
  set_connectivity(record.job_id, input.rest.faces);
  jobs::RunControls controls;
  controls.cancel = &active.token;
  controls.progress = progress_publisher(record, spec);

  const jobs::SimulateOutcome outcome = jobs::run_simulate(input, controls);
  if (active.stop_reason != static_cast<int>(StopReason::None)) {
    finish_stopped(record, active);
    return;
  }
  store::ResultRecord result;
  result.converged = outcome.result.converged;
  result.rest_mesh = store::encode_mesh_blob(input.rest);
  result.inflated_mesh = store::encode_mesh_blob(TriMesh{outcome.result.deformed, input.rest.faces});
  result.report_json = outcome.report_json;
  if (!m_jobs.mark_completed(record.row_id, result)) return;  // cancelled as it finished: that already published
  const std::string message = outcome.result.converged
                                  ? "completed: converged in " + format_number(outcome.result.time_s) + " s"
                                  : "completed without converging: " + outcome.result.message;
  log("job " + record.job_id + " " + message);
  v1::JobEvent done = state_event(record.job_id, v1::JOB_STATE_COMPLETED, message);
  done.set_converged(outcome.result.converged);
  close_watchers(record.job_id, std::move(done));
}

void JobHandler::set_connectivity(const std::string& job_id, const Faces& faces) {
  auto triangles = std::make_shared<std::vector<std::uint32_t>>();
  triangles->reserve(static_cast<std::size_t>(faces.size()));
  for (Eigen::Index i = 0; i < faces.size(); ++i) triangles->push_back(static_cast<std::uint32_t>(faces.data()[i]));
  std::lock_guard lock(m_watch_mutex);
  m_connectivity[job_id] = std::move(triangles);
}

ProgressCallback JobHandler::progress_publisher(const store::JobRecord& record, const v1::JobSpec& spec) {
  const int mesh_every = spec.progress_mesh_every() != 0 ? spec.progress_mesh_every() : m_options.progress_mesh_every;
  // The callback is copied into the solver's options: its counters live behind one shared pointer.
  struct State {
    int shape_events = 0;
    std::chrono::steady_clock::time_point last_checkpoint{}, last_shape_checkpoint{};
  };
  auto state = std::make_shared<State>();
  const std::int64_t row_id = record.row_id;
  const std::string job_id = record.job_id;
  return [this, state, mesh_every, row_id, job_id](const ProgressEvent& progress) {
    v1::JobEvent event;
    event.set_job_id(job_id);
    event.set_state(v1::JOB_STATE_RUNNING);
    event.set_time_ms(now_ms());
    store::ProgressRecord checkpoint;
    checkpoint.phase = progress.phase;
    checkpoint.iteration = progress.iteration;
    checkpoint.elapsed_s = progress.elapsed_s;
    checkpoint.residual_norm = progress.residual_norm;
    checkpoint.pressure_kpa = progress.pressure_kpa;
    checkpoint.avg_error_mm = progress.avg_error_mm;
    checkpoint.max_error_mm = progress.max_error_mm;
    checkpoint.recorded_ms = event.time_ms();
    fill_progress(checkpoint, event.mutable_progress());
    if (progress.shape != nullptr && mesh_every > 0 && state->shape_events++ % mesh_every == 0) {
      v1::IntermediateMesh* mesh = event.mutable_mesh();
      mesh->set_vertex_count(static_cast<std::uint32_t>(progress.shape->rows()));
      mesh->set_iteration(progress.iteration);
      mesh->mutable_positions_mm()->Reserve(static_cast<int>(progress.shape->size()));
      for (Eigen::Index i = 0; i < progress.shape->size(); ++i)
        mesh->add_positions_mm(static_cast<float>(progress.shape->data()[i]));
    }
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - state->last_checkpoint).count() >= m_options.checkpoint_interval_s) {
      std::string shape;
      if (progress.shape != nullptr &&
          std::chrono::duration<double>(now - state->last_shape_checkpoint).count() >= SHAPE_CHECKPOINT_INTERVAL_S) {
        shape = store::encode_positions_f32(*progress.shape);
        state->last_shape_checkpoint = now;
      }
      m_jobs.append_progress(row_id, checkpoint, shape);
      state->last_checkpoint = now;
    }
    publish(job_id, std::move(event));
  };
}

void JobHandler::run_design_job(const store::JobRecord& record, const v1::JobSpec& spec, ActiveJob& active) {
  // The limit on vertices was applied at submit time; a job accepted then runs now even if the limit shrank.
  LoadedDesign loaded = load_design(spec.design(), record.owner, 0, m_materials);
  if (!loaded.input) {
    m_jobs.mark_failed(record.row_id, loaded.error);
    log("job " + record.job_id + " failed: " + loaded.error);
    close_watchers(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, loaded.error));
    return;
  }
  const jobs::DesignInput& input = *loaded.input;
  set_connectivity(record.job_id, input.target.mesh.faces);
  jobs::RunControls controls;
  controls.cancel = &active.token;
  controls.progress = progress_publisher(record, spec);

  const jobs::DesignOutcome outcome = jobs::run_design(input, controls);
  if (active.stop_reason != static_cast<int>(StopReason::None)) {
    finish_stopped(record, active);
    return;
  }
  if (outcome.result.rest.vertex_count() == 0) {
    const std::string error = "the design produced no rest shape: " + outcome.result.message;
    m_jobs.mark_failed(record.row_id, error);
    log("job " + record.job_id + " failed: " + error);
    close_watchers(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, error));
    return;
  }
  store::ResultRecord result;
  result.converged = outcome.result.converged;
  result.rest_mesh = store::encode_mesh_blob(outcome.result.rest);
  result.inflated_mesh = store::encode_mesh_blob(TriMesh{outcome.result.inflated, outcome.result.rest.faces});
  result.report_json = outcome.report_json;
  if (!m_jobs.mark_completed(record.row_id, result)) return;  // cancelled as it finished: that already published
  const std::string errors = jobs::design_error_summary(outcome.result);
  const std::string message = (outcome.result.converged ? "completed: converged in " : "completed without converging in ") +
                              format_number(outcome.result.time_s) + " s, " + errors +
                              (outcome.result.converged ? std::string() : ": " + outcome.result.message);
  log("job " + record.job_id + " " + message);
  v1::JobEvent done = state_event(record.job_id, v1::JOB_STATE_COMPLETED, message);
  done.set_converged(outcome.result.converged);
  close_watchers(record.job_id, std::move(done));
}

void JobHandler::run_fit_job(const store::JobRecord& record, const v1::JobSpec& spec, ActiveJob& active) {
  const auto fail_job = [&](const std::string& error) {
    m_jobs.mark_failed(record.row_id, error);
    log("job " + record.job_id + " failed: " + error);
    close_watchers(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, error));
  };
  const v1::FitMaterialJob& job = spec.fit_material();
  std::optional<jobs::FitInput> input;
  if (const ServiceStatus checked = check_fit(job, &input); !checked.ok()) return fail_job(checked.message);
  // The fit has no iteration callback: it cannot be stopped midway, only its outcome discarded.
  Result<jobs::FitOutcome> outcome = jobs::run_fit(*input);
  if (active.stop_reason != static_cast<int>(StopReason::None)) {
    finish_stopped(record, active);
    return;
  }
  if (!outcome) return fail_job(outcome.error());
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
    const ServiceStatus status = m_materials.put(Caller{record.owner}, put, &stored_material);
    if (!status.ok()) return fail_job("storing material '" + job.name() + "': " + status.message);
    stored_note = ", stored as " + stored_material.name();
  }
  store::ResultRecord result;
  result.converged = true;
  for (const FitResult& fit : outcome->fits) result.converged = result.converged && fit.converged;
  result.report_json = jobs::fit_report_json(*input, *outcome);
  if (!m_jobs.mark_completed(record.row_id, result)) return;  // cancelled as it finished: that already published
  const std::string message = "completed: best fit " + material_spec(best.material) + " in " +
                              format_number(outcome->time_s) + " s" + stored_note;
  log("job " + record.job_id + " " + message);
  v1::JobEvent done = state_event(record.job_id, v1::JOB_STATE_COMPLETED, message);
  done.set_converged(result.converged);
  close_watchers(record.job_id, std::move(done));
}

void JobHandler::finish_stopped(const store::JobRecord& record, ActiveJob& active) {
  switch (static_cast<StopReason>(active.stop_reason.load())) {
    case StopReason::Shutdown:
      m_jobs.mark_requeued(record.row_id);
      log("job " + record.job_id + " interrupted by shutdown; it runs again at the next start");
      break;
    case StopReason::TimeLimit: {
      const std::string error = "time limit of " + format_number(active.time_limit_s) + " s exceeded";
      m_jobs.mark_failed(record.row_id, error);
      log("job " + record.job_id + " failed: " + error);
      close_watchers(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, error));
      break;
    }
    case StopReason::Cancelled:
      log("job " + record.job_id + " stopped after cancellation");
      break;
    case StopReason::None: break;
  }
}

void JobHandler::shutdown() {
  if (m_stopping.exchange(true)) return;
  m_queue.close();
  {
    std::lock_guard lock(m_active_mutex);
    for (auto& [row, active] : m_active) {
      int expected = static_cast<int>(StopReason::None);
      active->stop_reason.compare_exchange_strong(expected, static_cast<int>(StopReason::Shutdown));
      active->token.cancel();
    }
  }
  m_watchdog_wake.notify_all();
  for (std::thread& worker : m_workers)
    if (worker.joinable()) worker.join();
  if (m_watchdog.joinable()) m_watchdog.join();
  std::vector<std::shared_ptr<WatchChannel>> channels;
  {
    std::lock_guard lock(m_watch_mutex);
    for (auto& [job_id, channel] : m_watchers) channels.push_back(channel);
    m_watchers.clear();
  }
  for (const auto& channel : channels)
    channel->close(std::nullopt, ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down"));
  if (m_lock_fd >= 0) {
    ::close(m_lock_fd);  // releases the flock
    m_lock_fd = -1;
  }
}

int JobHandler::running_count() const {
  std::lock_guard lock(m_active_mutex);
  return static_cast<int>(m_active.size());
}

}  // namespace balloon::service
