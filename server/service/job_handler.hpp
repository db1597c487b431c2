#pragma once
/// The job side of the service: submit (check, store, queue), get, list, cancel, watch and results,
/// with the worker threads that run queued jobs. Takes and returns API messages; knows nothing of gRPC
/// (the adapter in server/rpc converts statuses and streams).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "progress.hpp"
#include "service/caller.hpp"
#include "service/job_queue.hpp"
#include "service/material_handler.hpp"
#include "service/service_options.hpp"
#include "service/service_status.hpp"
#include "service/watch_channel.hpp"
#include "store/job_store.hpp"

namespace balloon::service {

class JobHandler {
 public:
  JobHandler(const ServiceOptions& options, store::Store& store, MaterialHandler& materials);
  /// Stops the workers (running jobs go back to the queue in the store) if shutdown() was not called.
  ~JobHandler();
  JobHandler(const JobHandler&) = delete;
  JobHandler& operator=(const JobHandler&) = delete;

  /// Re-queues unfinished jobs from the store (when this process is the store's only user) and starts
  /// the workers. Returns the number of jobs recovered.
  int start();

  /// Checks the job (mesh, material, options) and returns once it is stored and queued.
  ServiceStatus submit(const Caller& caller, const balloon::v1::SubmitJobRequest& request,
                       balloon::v1::SubmitJobResponse* reply);
  ServiceStatus get(const Caller& caller, const balloon::v1::GetJobRequest& request, balloon::v1::Job* reply);
  ServiceStatus list(const Caller& caller, const balloon::v1::ListJobsRequest& request,
                     balloon::v1::ListJobsResponse* reply);
  /// Queued: removed at once. Running: stopped within one solver iteration; the state is CANCELLED at once.
  ServiceStatus cancel(const Caller& caller, const balloon::v1::CancelJobRequest& request, balloon::v1::Job* reply);
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
  enum class StopReason : int { None = 0, Cancelled = 1, TimeLimit = 2, Shutdown = 3 };

  /// A job on a worker.
  struct ActiveJob {
    std::string job_id;
    balloon::CancelToken token;
    std::atomic<int> stop_reason{0};
    double time_limit_s = 0.0;
    std::chrono::steady_clock::time_point started;
  };

  void worker_loop();
  void watchdog_loop();
  void run_job(std::int64_t row_id);
  /// Runs a simulate job to its end state (completed, failed, cancelled or re-queued) and publishes it.
  void run_simulate_job(const store::JobRecord& record, const balloon::v1::JobSpec& spec, ActiveJob& active);
  /// Runs a design job (jobs/design_job) to its end state and publishes it, like run_simulate_job.
  void run_design_job(const store::JobRecord& record, const balloon::v1::JobSpec& spec, ActiveJob& active);
  /// Runs a material-fit job (jobs/fit_job): the report JSON is its result; with a name, the best fit is
  /// stored as the owner's material (with its provenance) before the job completes.
  void run_fit_job(const store::JobRecord& record, const balloon::v1::JobSpec& spec, ActiveJob& active);
  /// The triangles the first intermediate mesh of a job's watchers carries.
  void set_connectivity(const std::string& job_id, const Faces& faces);
  /// A progress callback that publishes a running job's events (with the intermediate mesh every K
  /// events) and checkpoints them in the store at most every checkpoint_interval_s.
  ProgressCallback progress_publisher(const store::JobRecord& record, const balloon::v1::JobSpec& spec);
  /// Records a job that stopped early: cancelled (already stored), timed out, or re-queued at shutdown.
  void finish_stopped(const store::JobRecord& record, ActiveJob& active);
  bool acquire_store_lock();

  void publish(const std::string& job_id, balloon::v1::JobEvent event);
  void close_watchers(const std::string& job_id, balloon::v1::JobEvent last_event);
  void fill_job(const store::JobRecord& record, balloon::v1::Job* job) const;
  std::optional<store::JobRecord> find_owned(const Caller& caller, const std::string& job_id);
  std::string new_job_id();
  void log(const std::string& line) const;

  ServiceOptions m_options;
  store::Store& m_store;
  store::JobStore m_jobs;
  MaterialHandler& m_materials;
  JobQueue m_queue;

  mutable std::mutex m_active_mutex;
  std::map<std::int64_t, std::shared_ptr<ActiveJob>> m_active;

  std::mutex m_watch_mutex;
  std::multimap<std::string, std::shared_ptr<WatchChannel>> m_watchers;
  std::map<std::string, std::shared_ptr<const std::vector<std::uint32_t>>> m_connectivity;

  std::vector<std::thread> m_workers;
  std::thread m_watchdog;
  std::mutex m_watchdog_mutex;
  std::condition_variable m_watchdog_wake;
  std::atomic<bool> m_stopping{false};
  bool m_started = false;
  int m_lock_fd = -1;

  std::mutex m_id_mutex;
  std::uint64_t m_id_state = 0;
};

}  // namespace balloon::service
