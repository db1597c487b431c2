#pragma once
/// The worker threads that run queued jobs, the jobs they are running, and the watchdog that stops a
/// job past its time limit. Knows nothing of what a job does: `run` does that.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "progress.hpp"
#include "service/job_queue.hpp"

namespace balloon::service {

/// Why a running job was told to stop (the first reason wins).
enum class StopReason : int { None = 0, Cancelled = 1, TimeLimit = 2, Shutdown = 3 };

/// A job on a worker.
struct ActiveJob {
  std::int64_t row_id = 0;
  std::string job_id;
  std::string owner;
  balloon::CancelToken token;
  std::atomic<int> stop_reason{0};
  double time_limit_s = 0.0;  ///< 0: none
  std::chrono::steady_clock::time_point started;

  /// Records `reason` (unless another came first) and fires the cancel token.
  void stop(StopReason reason);
  StopReason reason() const { return static_cast<StopReason>(stop_reason.load()); }
};

class WorkerPool {
 public:
  /// `run` is called on a worker with each row id popped from `queue`; it must not throw (a throw is
  /// caught and logged through `log`).
  WorkerPool(JobQueue& queue, std::function<void(std::int64_t)> run, std::function<void(const std::string&)> log);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Starts `workers` threads and the watchdog.
  void start(int workers);
  /// Registers a job that starts running on this thread. A job entered after shutdown began is stopped
  /// at once (reason Shutdown).
  std::shared_ptr<ActiveJob> enter(std::int64_t row_id, const std::string& job_id, const std::string& owner,
                                   double time_limit_s);
  /// The job is no longer running.
  void leave(std::int64_t row_id);
  /// Stops a running job; false if it is not running here.
  bool stop(std::int64_t row_id, StopReason reason);
  /// Jobs of `owner` running now (all owners when empty).
  int running_count(const std::string& owner = "") const;

  /// Closes the queue, stops every running job (reason Shutdown) and joins the threads. Idempotent.
  void shutdown();
  bool stopping() const { return m_stopping; }

 private:
  void worker_loop();
  void watchdog_loop();

  JobQueue& m_queue;
  std::function<void(std::int64_t)> m_run;
  std::function<void(const std::string&)> m_log;

  mutable std::mutex m_active_mutex;
  std::map<std::int64_t, std::shared_ptr<ActiveJob>> m_active;

  std::vector<std::thread> m_workers;
  std::thread m_watchdog;
  std::mutex m_watchdog_mutex;
  std::condition_variable m_watchdog_wake;
  std::atomic<bool> m_stopping{false};
};

}  // namespace balloon::service
