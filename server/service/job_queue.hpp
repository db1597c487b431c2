#pragma once
/// A bounded priority queue of job row ids shared by the submitters and the workers: higher priority
/// first, then first come first served. Capacity is reserved before a job is stored, so a job that
/// reached the database always fits in the queue.
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <set>

namespace balloon::service {

class JobQueue {
 public:
  /// At most `capacity` queued jobs (running ones do not count).
  explicit JobQueue(std::size_t capacity) : m_capacity(capacity) {}

  /// Takes a slot for a job about to be stored; false if the queue is full.
  bool reserve();
  /// Gives a reserved slot back (the job was not stored after all).
  void release_reservation();
  /// Queues a job into a slot taken with reserve().
  void push_reserved(std::int64_t row_id, int priority);
  /// Queues a job found in the store at start-up, whatever the capacity: nothing accepted is dropped.
  void push_recovered(std::int64_t row_id, int priority);

  /// The next job, blocking while the queue is empty; nullopt once the queue is closed.
  std::optional<std::int64_t> pop();
  /// Removes a queued job (cancelled); false if it is not queued here.
  bool remove(std::int64_t row_id);
  /// Number of jobs that will run before this one; -1 if it is not queued here.
  int position(std::int64_t row_id) const;
  std::size_t size() const;
  std::size_t capacity() const { return m_capacity; }
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
  void push_locked(std::int64_t row_id, int priority);

  const std::size_t m_capacity;
  mutable std::mutex m_mutex;
  std::condition_variable m_ready;
  std::set<Entry> m_entries;
  std::size_t m_reserved = 0;
  std::uint64_t m_next_sequence = 0;
  bool m_closed = false;
};

}  // namespace balloon::service
