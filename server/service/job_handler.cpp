#include "service/job_handler.hpp"
#include "service/shard_name.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>

#include "mesh/mesh_io.hpp"
#include "store/mesh_blob.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;
using store::JobState;

constexpr int MAX_PAGE_SIZE = 1000;
constexpr int DEFAULT_PAGE_SIZE = 100;
constexpr double SHAPE_CHECKPOINT_INTERVAL_S = 1.0;  // stored shapes are big: at most one a second per job
// Progress rows go to the store in one transaction per this interval per job (the first at once, the
// rest when the run ends): a crash loses at most the rows of the last interval, never a result.
constexpr double PROGRESS_BATCH_INTERVAL_S = 1.0;
constexpr int FAIL_WRITE_ATTEMPTS = 3;
constexpr std::size_t MAX_REQUEST_ID_LENGTH = 128;
constexpr std::size_t MAX_PREPARED = 4;  // decoded jobs kept from submit to run (a few meshes in memory)
constexpr std::chrono::hours RETENTION_INTERVAL{1};  // how often old finished jobs are deleted
constexpr std::int64_t REQUEST_ID_WINDOW_MS = 24LL * 3600 * 1000;  // a repeat within 24 h returns the first job

/// NOT_FOUND for a job id, quoting at most 64 characters of it: a hostile 100 kB id would otherwise come
/// back in the status message and overflow the client's metadata limit.
ServiceStatus job_not_found(const std::string& job_id) {
  constexpr std::size_t SHOWN = 64;
  const std::string shown = job_id.size() > SHOWN ? job_id.substr(0, SHOWN) + "..." : job_id;
  return ServiceStatus::error(StatusCode::NotFound, "no job '" + shown + "'");
}

/// Empty when `request_id` is a usable idempotency key, else the problem.
std::string request_id_problem(const std::string& request_id) {
  if (request_id.size() > MAX_REQUEST_ID_LENGTH)
    return "request_id is " + std::to_string(request_id.size()) + " characters long, over the limit of " +
           std::to_string(MAX_REQUEST_ID_LENGTH);
  for (const char c : request_id)
    if (c < 0x21 || c > 0x7e) return "request_id must be printable ASCII without spaces";
  return "";
}               // tries to record a failure before leaving it to the next start
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
  const JobKind* found = job_kind_named(kind);
  return found ? found->proto_kind() : v1::JOB_KIND_UNSPECIFIED;
}

std::int64_t now_ms() { return store::now_ms(); }

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

JobHandler::JobHandler(const ServiceOptions& options, store::Store& store, MaterialHandler& materials)
    : m_options(options), m_store(store), m_jobs(store), m_materials(materials),
      m_queue(static_cast<std::size_t>(std::max(1, options.max_queue)), options.max_queued_per_tenant,
              options.max_running_per_tenant),
      m_pool(m_queue, [this](std::int64_t row_id) { run_job(row_id); }, options.log) {
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
    const store::JobStore::Recovery recovery = m_jobs.recover_unfinished(m_options.max_attempts);
    for (const store::JobRecord& job : recovery.crashed) log("job " + job.job_id + " failed: " + job.error);
    // Re-queued in the store either way (no job stays "running" with nothing running it).
    if (m_options.run_recovered) {
      for (const store::JobRecord& job : recovery.queued) {
        m_queue.push_recovered(job.row_id, job.owner, job.priority);
        ++recovered;
      }
    }
    if (recovered > 0) log("recovered " + std::to_string(recovered) + " unfinished job(s) from " + m_store.path());
  } else if (!sole_user) {
    log("another process uses " + m_store.path() + "; not recovering its unfinished jobs");
  }
  if (m_lock_fd >= 0 && sole_user) ::flock(m_lock_fd, LOCK_SH);  // let other processes share the store now
  m_pool.start(m_options.workers);
  if (m_options.retention_days > 0.0 && sole_user) {
    apply_retention();
    m_retention = std::thread([this] { retention_loop(); });
  }
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
  if (m_pool.stopping()) return ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down");
  const v1::JobSpec& spec = request.spec();
  const JobKind* kind = job_kind_for(spec);
  if (kind == nullptr)
    return ServiceStatus::error(StatusCode::InvalidArgument, "spec names no job (simulate, design or fit_material)");
  if (spec.priority() < -100 || spec.priority() > 100)
    return ServiceStatus::bad_field("priority", "priority must be within -100..100");
  if (spec.priority() > 0 && !caller.may_raise_priority)
    return ServiceStatus::field_error(StatusCode::PermissionDenied, "priority",
                                      "priority above 0 is only for tenants marked 'raise-priority' in the token file");
  if (!std::isfinite(spec.time_limit_s()) || spec.time_limit_s() < 0.0)
    return ServiceStatus::bad_field("time_limit_s", "time_limit_s must be a finite number >= 0 (s)");

  const std::string& request_id = request.request_id();
  if (const std::string problem = request_id_problem(request_id); !problem.empty())
    return ServiceStatus::bad_field("request_id", problem);
  // A retry of a submission that reached the store returns the first job: nothing is parsed or stored.
  const auto first_submission = [&]() -> std::optional<store::JobRecord> {
    if (request_id.empty()) return std::nullopt;
    return m_jobs.find_request(caller.tenant, request_id, now_ms() - REQUEST_ID_WINDOW_MS);
  };
  if (const auto first = first_submission()) {
    fill_job(*first, reply->mutable_job());
    return ServiceStatus::success();
  }

  // The queue and quota checks come before any parsing: a refused job costs the server nothing.
  switch (m_queue.reserve(caller.tenant)) {
    case JobQueue::Reservation::Reserved: break;
    case JobQueue::Reservation::QueueFull:
      return ServiceStatus::error(StatusCode::ResourceExhausted, "the queue is full (" +
                                                                     std::to_string(m_queue.capacity()) +
                                                                     " jobs waiting); retry later");
    case JobQueue::Reservation::TenantFull:
      return ServiceStatus::error(StatusCode::ResourceExhausted,
                                  "quota max-queued-per-tenant: " + std::to_string(m_options.max_queued_per_tenant) +
                                      " jobs of yours are queued, the limit; retry when some have started");
  }
  if (m_options.max_stored_mb_per_tenant > 0) {
    const std::int64_t limit = static_cast<std::int64_t>(m_options.max_stored_mb_per_tenant) << 20;
    const std::int64_t stored = m_jobs.stored_bytes(caller.tenant);
    if (stored + static_cast<std::int64_t>(request.ByteSizeLong()) > limit) {
      m_queue.release_reservation(caller.tenant);
      char used[32];
      std::snprintf(used, sizeof(used), "%.1f", static_cast<double>(stored) / (1 << 20));
      return ServiceStatus::error(StatusCode::ResourceExhausted,
                                  "quota max-stored-mb-per-tenant: your jobs store " + std::string(used) +
                                      " MiB, the limit is " + std::to_string(m_options.max_stored_mb_per_tenant) +
                                      " MiB with this job; delete finished jobs (DeleteJob) first");
    }
  }
  CheckedJob checked;
  ServiceStatus status;
  try {
    status = kind->check(spec, CheckContext{caller, m_materials, m_options.max_mesh_vertices}, &checked);
  } catch (...) {
    m_queue.release_reservation(caller.tenant);
    throw;
  }
  if (!status.ok()) {
    m_queue.release_reservation(caller.tenant);
    return status;
  }
  store::JobRecord record;
  record.job_id = new_job_id();
  record.owner = caller.tenant;
  record.kind = kind->name();
  record.state = JobState::Queued;
  record.priority = spec.priority();
  record.summary = checked.summary;
  record.created_ms = now_ms();
  if (!checked.stored_spec.SerializeToString(&record.spec)) {
    m_queue.release_reservation(caller.tenant);
    return ServiceStatus::error(StatusCode::Internal, "could not serialize the job spec");
  }
  record.request_id = request_id;
  {
    // Two copies of one request in flight at once: the second waits for the first and finds it here.
    const RequestClaims::Claim claim = m_request_claims.claim(caller.tenant, request_id);
    try {
      if (const auto first = first_submission()) {
        m_queue.release_reservation(caller.tenant);
        fill_job(*first, reply->mutable_job());
        return ServiceStatus::success();
      }
      m_jobs.insert(record);
    } catch (...) {
      m_queue.release_reservation(caller.tenant);
      throw;
    }
  }
  if (checked.prepared) {
    std::lock_guard lock(m_prepared_mutex);
    m_prepared[record.row_id] = std::move(checked.prepared);
    if (m_prepared.size() > MAX_PREPARED) m_prepared.erase(m_prepared.begin());
  }
  m_queue.push_reserved(record.row_id, record.owner, record.priority);
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
  if (!record) return job_not_found(request.job_id());
  fill_job(*record, reply);
  return ServiceStatus::success();
}

ServiceStatus JobHandler::list(const Caller& caller, const v1::ListJobsRequest& request, v1::ListJobsResponse* reply) {
  int page_size = request.page_size() == 0 ? DEFAULT_PAGE_SIZE : request.page_size();
  if (page_size < 0 || page_size > MAX_PAGE_SIZE)
    return ServiceStatus::bad_field("page_size", "page_size must be within 1..1000");
  std::int64_t before_row = 0;
  if (!request.page_token().empty()) {
    char* end = nullptr;
    errno = 0;
    before_row = std::strtoll(request.page_token().c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE || before_row <= 0)
      return ServiceStatus::bad_field("page_token", "page_token is not one this server gave out");
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
  if (!record) return job_not_found(request.job_id());
  if (!store::is_terminal(record->state)) {
    // The store first: if its write fails the job is still queued (in memory and on disk) and the caller
    // gets an error; a worker that pops it meanwhile finds it cancelled and skips it.
    const std::string reason = "cancelled by its owner";
    const bool cancelled = m_jobs.mark_cancelled(record->row_id, reason);
    m_queue.remove(record->row_id);
    if (cancelled) {
      // A running job stops at its next iteration; its state is final already.
      m_pool.stop(record->row_id, StopReason::Cancelled);
      log("job " + record->job_id + " cancelled");
      m_watches.finish(record->job_id, state_event(record->job_id, v1::JOB_STATE_CANCELLED, reason));
    }
    record = m_jobs.find(request.job_id());
  }
  fill_job(*record, reply);
  return ServiceStatus::success();
}

ServiceStatus JobHandler::remove(const Caller& caller, const v1::DeleteJobRequest& request, v1::DeleteJobResponse*) {
  const auto record = find_owned(caller, request.job_id());
  if (!record) return job_not_found(request.job_id());
  if (!store::is_terminal(record->state) || !m_jobs.delete_finished(record->row_id))
    return ServiceStatus::error(StatusCode::FailedPrecondition,
                                "job " + record->job_id + " is " + store::to_string(record->state) +
                                    "; cancel it before deleting it");
  log("job " + record->job_id + " deleted by its owner");
  return ServiceStatus::success();
}

void JobHandler::apply_retention() {
  const std::int64_t cutoff = now_ms() - static_cast<std::int64_t>(m_options.retention_days * 86400e3);
  try {
    const int deleted = m_jobs.delete_finished_before(cutoff);
    if (deleted > 0)
      log("retention: deleted " + std::to_string(deleted) + " job(s) finished more than " +
          format_number(m_options.retention_days) + " days ago");
  } catch (const std::exception& error) {
    log(std::string("retention: could not delete old jobs: ") + error.what());
  }
}

void JobHandler::retention_loop() {
  std::unique_lock lock(m_retention_mutex);
  while (!m_retention_wake.wait_for(lock, RETENTION_INTERVAL, [this] { return m_retention_stop; })) {
    lock.unlock();
    apply_retention();
    lock.lock();
  }
}

ServiceStatus JobHandler::watch(const Caller& caller, const v1::WatchJobRequest& request,
                                std::shared_ptr<WatchChannel>* channel) {
  if (m_pool.stopping()) return ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down");
  if (!find_owned(caller, request.job_id()))
    return job_not_found(request.job_id());
  // The snapshot is taken under the hub's lock: publishers wait, so the snapshot comes first.
  const auto first_events = [&](WatchChannel& opened, bool* subscribe) {
    const auto record = m_jobs.find(request.job_id());
    if (!record) return job_not_found(request.job_id());
    v1::JobEvent snapshot = state_event(record->job_id, to_proto(record->state), "");
    if (record->last_progress) fill_progress(*record->last_progress, snapshot.mutable_progress());
    snapshot.set_converged(record->converged);
    if (store::is_terminal(record->state)) {
      snapshot.set_message(record->error.empty() ? std::string("finished") : record->error);
      opened.close(std::move(snapshot), ServiceStatus::success());
    } else {
      snapshot.set_message(record->state == JobState::Queued ? "queued" : "running");
      opened.push(std::move(snapshot), nullptr);
      *subscribe = true;
    }
    return ServiceStatus::success();
  };
  return m_watches.open(request.job_id(), caller.tenant, m_options.max_watches_per_tenant, first_events, channel);
}

void JobHandler::unwatch(const std::shared_ptr<WatchChannel>& channel) { m_watches.close(channel); }

ServiceStatus JobHandler::result(const Caller& caller, const v1::GetResultRequest& request, v1::JobResult* reply) {
  const auto record = find_owned(caller, request.job_id());
  if (!record) return job_not_found(request.job_id());
  if (record->state != JobState::Completed) {
    std::string why = "job " + record->job_id + " is " + store::to_string(record->state);
    if (!record->error.empty()) why += " (" + record->error + ")";
    return ServiceStatus::error(StatusCode::FailedPrecondition, why + "; it has no result");
  }
  const v1::MeshFormat format = request.format() == v1::MESH_FORMAT_UNSPECIFIED ? v1::MESH_FORMAT_OBJ : request.format();
  const std::string extension = mesh_format_extension(format);
  if (extension.empty() || !is_writable_mesh_format(extension))
    return ServiceStatus::bad_field("format", "meshes can be returned as OBJ, STL or PLY only");
  const JobKind* kind = job_kind_named(record->kind);
  if (kind == nullptr)
    return ServiceStatus::error(StatusCode::Internal, "job " + record->job_id + " has an unknown kind");
  const auto stored = m_jobs.result(record->row_id);
  if (!stored) return ServiceStatus::error(StatusCode::Internal, "job " + record->job_id + " has lost its result");
  reply->set_job_id(record->job_id);
  return kind->fill_result(*stored, format, reply, request.inflated_mesh_only());
}

void JobHandler::run_job(std::int64_t row_id) {
  std::shared_ptr<const void> prepared;
  {
    std::lock_guard lock(m_prepared_mutex);
    if (const auto it = m_prepared.find(row_id); it != m_prepared.end()) {
      prepared = std::move(it->second);
      m_prepared.erase(it);
    }
  }
  std::optional<store::JobRecord> record = m_jobs.find_row(row_id);
  if (!record || record->state != JobState::Queued) return;
  if (!m_jobs.mark_running(row_id)) return;  // cancelled between pop and start
  record->state = JobState::Running;
  record->attempts += 1;

  v1::JobSpec spec;
  const std::optional<std::string> stored_spec = m_jobs.spec(row_id);
  const bool spec_ok = stored_spec && spec.ParseFromString(*stored_spec);
  const double time_limit_s = spec.time_limit_s() > 0.0 ? std::min(spec.time_limit_s(), m_options.job_time_limit_s)
                                                        : m_options.job_time_limit_s;
  const std::shared_ptr<ActiveJob> active = m_pool.enter(row_id, record->job_id, record->owner, time_limit_s);
  log("job " + record->job_id + " started (attempt " + std::to_string(record->attempts) + ")");
  m_watches.publish(record->job_id, state_event(record->job_id, v1::JOB_STATE_RUNNING,
                                                "started (attempt " + std::to_string(record->attempts) + ")"));
  try {
    const JobKind* kind = spec_ok ? job_kind_for(spec) : nullptr;
    if (kind == nullptr) {
      fail_job(*record, spec_ok ? "this server cannot run this kind of job" : "the stored job spec is unreadable");
    } else {
      std::function<void()> flush_progress;
      RunContext context{*record, spec, active->token, progress_publisher(*record, spec, &flush_progress),
                         [this, &record](const Faces& faces) { m_watches.set_connectivity(record->job_id, faces); },
                         m_materials, m_jobs.design_checkpoint(record->row_id), std::move(prepared)};
      if (time_limit_s > 0.0)
        context.deadline = active->started + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                 std::chrono::duration<double>(time_limit_s));
      RunOutcome outcome = kind->run(context);
      flush_progress();  // the last rows before the outcome, so a finished job has all of them
      finish_run(*record, *kind, *active, std::move(outcome));
    }
  } catch (const std::exception& error) {
    fail_job(*record, std::string("internal error: ") + error.what());
  }
  m_pool.leave(row_id);
}

void JobHandler::finish_run(const store::JobRecord& record, const JobKind&, const ActiveJob& active,
                            RunOutcome outcome) {
  if (active.reason() != StopReason::None || outcome.kind == RunOutcome::Kind::Stopped) {
    finish_stopped(record, active);
    return;
  }
  if (outcome.kind == RunOutcome::Kind::Failed) {
    fail_job(record, outcome.message);
    return;
  }
  if (!m_jobs.mark_completed(record.row_id, outcome.result)) return;  // cancelled as it finished: that already published
  log("job " + record.job_id + " " + outcome.message);
  v1::JobEvent done = state_event(record.job_id, v1::JOB_STATE_COMPLETED, outcome.message);
  done.set_converged(outcome.result.converged);
  m_watches.finish(record.job_id, std::move(done));
}

void JobHandler::fail_job(const store::JobRecord& record, const std::string& error) {
  // A store failure here must not leave the row in 'running' while the server lives on: retry a few
  // times; if the store still refuses, the next start applies the attempts rule to the row.
  for (int attempt = 1;; ++attempt) {
    try {
      m_jobs.mark_failed(record.row_id, error);
      break;
    } catch (const std::exception& store_error) {
      if (attempt == FAIL_WRITE_ATTEMPTS) {
        log("job " + record.job_id + ": could not record its failure (" + store_error.what() +
            "); the next start re-queues it or fails it by --max-attempts");
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100 * attempt));
    }
  }
  log("job " + record.job_id + " failed: " + error);
  m_watches.finish(record.job_id, state_event(record.job_id, v1::JOB_STATE_FAILED, error));
}

ProgressCallback JobHandler::progress_publisher(const store::JobRecord& record, const v1::JobSpec& spec,
                                                std::function<void()>* flush) {
  const int mesh_every = spec.progress_mesh_every() != 0 ? spec.progress_mesh_every() : m_options.progress_mesh_every;
  // The callback is copied into the solver's options: its counters live behind one shared pointer.
  // Progress rows are kept at most one per checkpoint_interval_s and written in batches, one transaction
  // per PROGRESS_BATCH_INTERVAL_S (the first row at once), with the latest shape; the rest at the end.
  struct State {
    std::mutex mutex;  // the publisher and the final flush may run on different threads
    int shape_events = 0;
    std::chrono::steady_clock::time_point last_checkpoint{}, last_shape_checkpoint{}, last_rest_checkpoint{},
        last_flush{};
    std::vector<store::ProgressRecord> pending;
    std::string pending_shape;
    std::size_t pending_shape_index = 0;
  };
  auto state = std::make_shared<State>();
  const std::int64_t row_id = record.row_id;
  const std::string job_id = record.job_id;
  const auto write_pending = [this, row_id](State& s) {
    // Called with s.mutex held; the store's own lock is taken inside (one short transaction, no fsync).
    if (s.pending.empty()) return;
    m_jobs.append_progress_batch(row_id, s.pending, s.pending_shape, s.pending_shape_index);
    s.pending.clear();
    s.pending_shape.clear();
  };
  *flush = [state, write_pending] {
    std::lock_guard lock(state->mutex);
    write_pending(*state);
  };
  return [this, state, mesh_every, row_id, job_id, write_pending](const ProgressEvent& progress) {
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
    std::lock_guard lock(state->mutex);
    if (progress.shape != nullptr && mesh_every > 0 && state->shape_events++ % mesh_every == 0) {
      v1::IntermediateMesh* mesh = event.mutable_mesh();
      mesh->set_vertex_count(static_cast<std::uint32_t>(progress.shape->rows()));
      mesh->set_iteration(progress.iteration);
      auto* positions = mesh->mutable_positions_mm();
      positions->Resize(static_cast<int>(progress.shape->size()), 0.0f);
      for (Eigen::Index i = 0; i < progress.shape->size(); ++i)
        positions->Set(static_cast<int>(i), static_cast<float>(progress.shape->data()[i]));
    }
    const auto now = std::chrono::steady_clock::now();
    bool recorded = false;  // this event's row is among the pending ones
    if (std::chrono::duration<double>(now - state->last_checkpoint).count() >= m_options.checkpoint_interval_s) {
      if (progress.shape != nullptr &&
          std::chrono::duration<double>(now - state->last_shape_checkpoint).count() >= SHAPE_CHECKPOINT_INTERVAL_S) {
        state->pending_shape = store::encode_positions_f32(*progress.shape);  // only the latest is kept
        state->pending_shape_index = state->pending.size();
        state->last_shape_checkpoint = now;
      }
      state->pending.push_back(checkpoint);
      state->last_checkpoint = now;
      recorded = true;
    }
    if (!state->pending.empty() &&
        std::chrono::duration<double>(now - state->last_flush).count() >= PROGRESS_BATCH_INTERVAL_S) {
      write_pending(*state);
      state->last_flush = now;
    }
    // A design's rest shape is what a restarted run continues from (issue 12): one kept per job.
    if (progress.rest_shape != nullptr && progress.iteration > 0 &&
        std::chrono::duration<double>(now - state->last_rest_checkpoint).count() >= SHAPE_CHECKPOINT_INTERVAL_S) {
      // The stored progress never lags the resume point: this event's row goes in first.
      if (!recorded) state->pending.push_back(checkpoint);
      write_pending(*state);
      state->last_flush = now;
      m_jobs.save_design_checkpoint(row_id, progress.iteration,
                                    store::encode_mesh_blob(TriMesh{*progress.rest_shape, Faces(0, 3)}));
      state->last_rest_checkpoint = now;
    }
    m_watches.publish(job_id, event);
  };
}

void JobHandler::finish_stopped(const store::JobRecord& record, const ActiveJob& active) {
  switch (active.reason()) {
    case StopReason::Shutdown:
      try {
        m_jobs.mark_requeued(record.row_id);
      } catch (const std::exception& error) {
        log("job " + record.job_id + ": could not re-queue it (" + error.what() + "); the next start does");
      }
      log("job " + record.job_id + " interrupted by shutdown; it runs again at the next start");
      break;
    case StopReason::TimeLimit:
      fail_job(record, "time limit of " + format_number(active.time_limit_s) + " s exceeded");
      break;
    case StopReason::Cancelled:
      log("job " + record.job_id + " stopped after cancellation");
      break;
    case StopReason::None: break;
  }
}

void JobHandler::shutdown() {
  {
    std::lock_guard lock(m_retention_mutex);
    m_retention_stop = true;
  }
  m_retention_wake.notify_all();
  if (m_retention.joinable()) m_retention.join();
  m_pool.shutdown();
  m_watches.close_all(ServiceStatus::error(StatusCode::Unavailable, "the server is shutting down"));
  if (m_lock_fd >= 0) {
    ::close(m_lock_fd);  // releases the flock
    m_lock_fd = -1;
  }
}

int JobHandler::running_count() const { return m_pool.running_count(); }

}  // namespace balloon::service
