#include "service/job_queue.hpp"

namespace balloon::service {

bool JobQueue::reserve() {
  std::lock_guard lock(m_mutex);
  if (m_closed || m_entries.size() + m_reserved >= m_capacity) return false;
  ++m_reserved;
  return true;
}

void JobQueue::release_reservation() {
  std::lock_guard lock(m_mutex);
  if (m_reserved > 0) --m_reserved;
}

void JobQueue::push_locked(std::int64_t row_id, int priority) {
  if (m_closed) return;
  m_entries.insert(Entry{priority, m_next_sequence++, row_id});
  m_ready.notify_one();
}

void JobQueue::push_reserved(std::int64_t row_id, int priority) {
  std::lock_guard lock(m_mutex);
  if (m_reserved > 0) --m_reserved;
  push_locked(row_id, priority);
}

void JobQueue::push_recovered(std::int64_t row_id, int priority) {
  std::lock_guard lock(m_mutex);
  push_locked(row_id, priority);
}

std::optional<std::int64_t> JobQueue::pop() {
  std::unique_lock lock(m_mutex);
  m_ready.wait(lock, [this] { return m_closed || !m_entries.empty(); });
  if (m_closed) return std::nullopt;
  const Entry entry = *m_entries.begin();
  m_entries.erase(m_entries.begin());
  return entry.row_id;
}

bool JobQueue::remove(std::int64_t row_id) {
  std::lock_guard lock(m_mutex);
  for (auto it = m_entries.begin(); it != m_entries.end(); ++it) {
    if (it->row_id == row_id) {
      m_entries.erase(it);
      return true;
    }
  }
  return false;
}

int JobQueue::position(std::int64_t row_id) const {
  std::lock_guard lock(m_mutex);
  int position = 0;
  for (const Entry& entry : m_entries) {
    if (entry.row_id == row_id) return position;
    ++position;
  }
  return -1;
}

std::size_t JobQueue::size() const {
  std::lock_guard lock(m_mutex);
  return m_entries.size();
}

void JobQueue::close() {
  std::lock_guard lock(m_mutex);
  m_closed = true;
  m_ready.notify_all();
}

}  // namespace balloon::service
