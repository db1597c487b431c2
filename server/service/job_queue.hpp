#pragma once
/// The queue of job row ids shared by the submitters and the workers. Fair between tenants: the next job
/// comes from the next tenant in turn (round-robin over tenants with queued jobs, skipping any at its
/// limit of running jobs), and within a tenant the highest priority first, then first come first served.
/// Capacity (overall and per tenant) is reserved before a job is stored, so a job that reached the
/// database always fits in the queue.
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>

namespace balloon::service {

class JobQueue {
 public:
  /// At most `capacity` queued jobs (running ones do not count), at most `max_queued_per_tenant` of one
  /// tenant, and at most `max_running_per_tenant` of one tenant popped and not yet done (0: no limit).
  explicit JobQueue(std::size_t capacity, int max_queued_per_tenant = 0, int max_running_per_tenant = 0)
      : m_capacity(capacity), m_max_queued_per_tenant(max_queued_per_tenant),
        m_max_running_per_tenant(max_running_per_tenant) {}

  enum class Reservation { Reserved, QueueFull, TenantFull };
  /// Takes a slot for a job of `tenant` about to be stored.
  Reservation reserve(const std::string& tenant);
  /// Gives a reserved slot back (the job was not stored after all).
  void release_reservation(const std::string& tenant);
  /// Queues a job into a slot taken with reserve().
  void push_reserved(std::int64_t row_id, const std::string& tenant, int priority);
  /// Queues a job found in the store at start-up, whatever the capacity: nothing accepted is dropped.
  void push_recovered(std::int64_t row_id, const std::string& tenant, int priority);

  /// A job handed to a worker.
  struct Popped {
    std::int64_t row_id = 0;
    std::string tenant;
  };
  /// The next job, blocking while no tenant has one it may run; nullopt once the queue is closed.
  /// The job counts as running for its tenant until done().
  std::optional<Popped> pop();
  /// A popped job of `tenant` has finished on its worker.
  void done(const std::string& tenant);
  /// Removes a queued job (cancelled); false if it is not queued here.
  bool remove(std::int64_t row_id);
  /// Number of jobs that will start before this one if every tenant could run (round-robin order);
  /// -1 if it is not queued here.
  int position(std::int64_t row_id) const;
  std::size_t size() const;
  std::size_t capacity() const { return m_capacity; }
  /// Jobs of `tenant` queued (and reserved).
  std::size_t queued(const std::string& tenant) const;
  /// Wakes every pop() with nullopt; later pushes are ignored.
  void close();

 private:
  struct Entry {
    int priority;
    std::uint64_t sequence;
    std::int64_t row_id;
    bool operator<(const Entry& other) const {
      if (priority != other.priority) return priority > other.priority;
      return sequence < other.sequence;
    }
  };
  struct Tenant {
    std::set<Entry> entries;
    std::size_t reserved = 0;
    int running = 0;
  };
  void push_locked(std::int64_t row_id, const std::string& tenant, int priority);
  /// The tenant whose turn it is, or end() when no tenant may run a job now.
  std::map<std::string, Tenant>::iterator next_tenant_locked();
  void forget_if_idle_locked(std::map<std::string, Tenant>::iterator tenant);

  const std::size_t m_capacity;
  const int m_max_queued_per_tenant;
  const int m_max_running_per_tenant;
  mutable std::mutex m_mutex;
  std::condition_variable m_ready;
  std::map<std::string, Tenant> m_tenants;
  std::string m_last_served;  // round-robin cursor: the tenant after this one goes next
  std::size_t m_queued = 0;
  std::size_t m_reserved = 0;
  std::uint64_t m_next_sequence = 0;
  bool m_closed = false;
};

}  // namespace balloon::service
