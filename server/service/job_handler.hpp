#pragma once
/// The job verbs of the service: submit (check, store, queue), get, list, cancel, watch and results, and
/// what a worker does with a queued job (run its kind, record the outcome). What each kind does lives in
/// its JobKind, the threads in WorkerPool, the watchers in WatchHub. Takes and returns API messages;
/// knows nothing of gRPC (the adapter in server/rpc converts statuses and streams).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "progress.hpp"
#include "service/caller.hpp"
#include "service/job_kind.hpp"
#include "service/job_queue.hpp"
#include "service/material_handler.hpp"
#include "service/request_claims.hpp"
#include "service/service_options.hpp"
#include "service/service_status.hpp"
#include "service/watch_channel.hpp"
#include "service/watch_hub.hpp"
#include "service/worker_pool.hpp"
#include "store/job_store.hpp"

namespace balloon::service {

class JobHandler {
 public:
  JobHandler(const ServiceOptions& options, store::Store& store, MaterialHandler& materials);
  /// Stops the workers (running jobs go back to the queue in the store) if shutdown() was not called.
  ~JobHandler();
  JobHandler(const JobHandler&) = delete;
  JobHandler& operator=(const JobHandler&) = delete;

  /// Re-queues unfinished jobs from the store (when this process is the store's only user; a job that
  /// already started max_attempts times FAILS instead), applies the retention and starts the workers.
  /// Returns the number of jobs recovered.
  int start();

  /// Checks the queue and the caller's quotas, then the job (mesh, material, options; cheap checks only:
  /// no remeshing), and returns once it is stored and queued. A request_id the caller used within 24 h
  /// returns that first job instead.
  ServiceStatus submit(const Caller& caller, const balloon::v1::SubmitJobRequest& request,
                       balloon::v1::SubmitJobResponse* reply);
  ServiceStatus get(const Caller& caller, const balloon::v1::GetJobRequest& request, balloon::v1::Job* reply);
  ServiceStatus list(const Caller& caller, const balloon::v1::ListJobsRequest& request,
                     balloon::v1::ListJobsResponse* reply);
  /// Queued: removed at once. Running: stopped within one solver iteration; the state is CANCELLED at once.
  ServiceStatus cancel(const Caller& caller, const balloon::v1::CancelJobRequest& request, balloon::v1::Job* reply);
  /// Deletes a finished job of the caller with its result. FAILED_PRECONDITION for a queued or running
  /// job (cancel it first), NOT_FOUND for a missing job or another tenant's.
  ServiceStatus remove(const Caller& caller, const balloon::v1::DeleteJobRequest& request,
                       balloon::v1::DeleteJobResponse* reply);
  /// Opens a channel that receives the job's current state, then its events until it finishes.
  ServiceStatus watch(const Caller& caller, const balloon::v1::WatchJobRequest& request,
                      std::shared_ptr<WatchChannel>* channel);
  /// Detaches a channel (its stream ended).
  void unwatch(const std::shared_ptr<WatchChannel>& channel);
  ServiceStatus result(const Caller& caller, const balloon::v1::GetResultRequest& request,
                       balloon::v1::JobResult* reply);

  /// Stops accepting jobs, stops running ones (they are re-queued in the store and run again at the
  /// next start), closes every watch stream with UNAVAILABLE and joins the workers. Idempotent.
  void shutdown();

  /// Jobs running right now.
  int running_count() const;

 private:
  void run_job(std::int64_t row_id);
  /// Records an outcome of a run: completed (result stored), failed, or stopped (finish_stopped).
  void finish_run(const store::JobRecord& record, const JobKind& kind, const ActiveJob& active, RunOutcome outcome);
  /// The one failure path: marks the job failed in the store, logs, and closes its watchers.
  void fail_job(const store::JobRecord& record, const std::string& error);
  /// A progress callback that publishes a running job's events (with the intermediate mesh every K
  /// events) and checkpoints them in the store at most every checkpoint_interval_s, in batches; `flush`
  /// receives the function that writes the rows still pending (called when the run ends).
  ProgressCallback progress_publisher(const store::JobRecord& record, const balloon::v1::JobSpec& spec,
                                      std::function<void()>* flush);
  /// Records a job that stopped early: cancelled (already stored), timed out, or re-queued at shutdown.
  void finish_stopped(const store::JobRecord& record, const ActiveJob& active);
  bool acquire_store_lock();
  /// Deletes finished jobs older than retention_days (at start, then hourly on its own thread).
  void apply_retention();
  void retention_loop();

  void fill_job(const store::JobRecord& record, balloon::v1::Job* job) const;
  std::optional<store::JobRecord> find_owned(const Caller& caller, const std::string& job_id);
  std::string new_job_id();
  void log(const std::string& line) const;

  ServiceOptions m_options;
  store::Store& m_store;
  store::JobStore m_jobs;
  MaterialHandler& m_materials;
  JobQueue m_queue;
  WatchHub m_watches;
  WorkerPool m_pool;

  std::thread m_retention;
  std::mutex m_retention_mutex;
  std::condition_variable m_retention_wake;
  bool m_retention_stop = false;

  bool m_started = false;
  int m_lock_fd = -1;

  /// Jobs checked at submit in this process, ready to run (CheckedJob::prepared), by row id: the run
  /// neither parses nor checks them again. At most MAX_PREPARED are kept (the oldest go first).
  std::mutex m_prepared_mutex;
  std::map<std::int64_t, std::shared_ptr<const void>> m_prepared;

  RequestClaims m_request_claims;  // each request_id held from its lookup to its insert
  std::mutex m_id_mutex;
  std::uint64_t m_id_state = 0;
};

}  // namespace balloon::service
