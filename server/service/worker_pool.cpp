#include "service/worker_pool.hpp"

#include <sys/resource.h>
#include <unistd.h>

namespace balloon::service {
namespace {

constexpr int WORKER_NICE = 10;  // the worker threads' niceness (the process's other threads keep theirs)

}  // namespace

void ActiveJob::stop(StopReason reason) {
  int expected = static_cast<int>(StopReason::None);
  stop_reason.compare_exchange_strong(expected, static_cast<int>(reason));
  token.cancel();
}

WorkerPool::WorkerPool(JobQueue& queue, std::function<void(std::int64_t)> run,
                       std::function<void(const std::string&)> log)
    : m_queue(queue), m_run(std::move(run)), m_log(std::move(log)) {}

WorkerPool::~WorkerPool() { shutdown(); }

void WorkerPool::start(int workers) {
  for (int i = 0; i < workers; ++i) m_workers.emplace_back([this] { worker_loop(); });
  m_watchdog = std::thread([this] { watchdog_loop(); });
}

void WorkerPool::worker_loop() {
  // Solving is batch work: below the threads that answer calls and stream events, so a submit or a
  // progress event is not queued behind a busy core (Linux: nice is per thread).
  ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), WORKER_NICE);
  while (const std::optional<JobQueue::Popped> popped = m_queue.pop()) {
    try {
      m_run(popped->row_id);
    } catch (const std::exception& error) {
      // A job must never take its worker down with it.
      if (m_log) m_log(std::string("worker: unexpected error: ") + error.what());
    }
    m_queue.done(popped->tenant);
  }
}

void WorkerPool::watchdog_loop() {
  std::unique_lock lock(m_watchdog_mutex);
  while (!m_stopping) {
    m_watchdog_wake.wait_for(lock, std::chrono::milliseconds(50));
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard active_lock(m_active_mutex);
    for (auto& [row, active] : m_active) {
      const double elapsed = std::chrono::duration<double>(now - active->started).count();
      if (active->time_limit_s > 0.0 && elapsed > active->time_limit_s) active->stop(StopReason::TimeLimit);
    }
  }
}

std::shared_ptr<ActiveJob> WorkerPool::enter(std::int64_t row_id, const std::string& job_id, const std::string& owner,
                                             double time_limit_s) {
  auto active = std::make_shared<ActiveJob>();
  active->row_id = row_id;
  active->job_id = job_id;
  active->owner = owner;
  active->time_limit_s = time_limit_s;
  active->started = std::chrono::steady_clock::now();
  std::lock_guard lock(m_active_mutex);
  m_active[row_id] = active;
  // A shutdown that began before we registered would miss this job: stop it ourselves.
  if (m_stopping) active->stop(StopReason::Shutdown);
  return active;
}

void WorkerPool::leave(std::int64_t row_id) {
  std::lock_guard lock(m_active_mutex);
  m_active.erase(row_id);
}

bool WorkerPool::stop(std::int64_t row_id, StopReason reason) {
  std::lock_guard lock(m_active_mutex);
  const auto it = m_active.find(row_id);
  if (it == m_active.end()) return false;
  it->second->stop(reason);
  return true;
}

int WorkerPool::running_count(const std::string& owner) const {
  std::lock_guard lock(m_active_mutex);
  if (owner.empty()) return static_cast<int>(m_active.size());
  int count = 0;
  for (const auto& [row, active] : m_active) count += active->owner == owner ? 1 : 0;
  return count;
}

void WorkerPool::shutdown() {
  if (m_stopping.exchange(true)) return;
  m_queue.close();
  {
    std::lock_guard lock(m_active_mutex);
    for (auto& [row, active] : m_active) active->stop(StopReason::Shutdown);
  }
  m_watchdog_wake.notify_all();
  for (std::thread& worker : m_workers)
    if (worker.joinable()) worker.join();
  if (m_watchdog.joinable()) m_watchdog.join();
}

}  // namespace balloon::service
