#include "service/watch_channel.hpp"

namespace balloon::service {

void WatchChannel::push(balloon::v1::JobEvent event,
                        const std::shared_ptr<const std::vector<std::uint32_t>>& triangles) {
  {
    std::lock_guard lock(m_mutex);
    if (m_closed) return;
    if (event.has_mesh() && !m_sent_connectivity) {
      if (!triangles) {
        event.clear_mesh();  // positions without connectivity would be unusable
      } else {
        event.mutable_mesh()->mutable_triangles()->Assign(triangles->begin(), triangles->end());
        m_sent_connectivity = true;
      }
    }
    m_events.push_back(std::move(event));
    trim_locked();
  }
  notify();
}

namespace {

std::size_t mesh_bytes(const balloon::v1::JobEvent& event) {
  if (!event.has_mesh()) return 0;
  return 4u * static_cast<std::size_t>(event.mesh().positions_mm_size() + event.mesh().triangles_size());
}

/// A state change (or the first snapshot) is never dropped; only a running job's progress reports are.
bool is_progress_only(const balloon::v1::JobEvent& event) {
  return event.state() == balloon::v1::JOB_STATE_RUNNING && event.message().empty();
}

}  // namespace

void WatchChannel::strip_mesh_locked(std::deque<balloon::v1::JobEvent>::iterator it) {
  if (it->mesh().triangles_size() > 0) {
    auto next = std::next(it);
    while (next != m_events.end() && !next->has_mesh()) ++next;
    if (next != m_events.end())
      next->mutable_mesh()->mutable_triangles()->Swap(it->mutable_mesh()->mutable_triangles());
    else
      m_sent_connectivity = false;  // the next mesh pushed carries them again
  }
  it->clear_mesh();
  ++m_dropped_meshes;
}

void WatchChannel::trim_locked() {
  // Meshes first: strip the oldest until the rest fit the budget; the newest always stays.
  std::size_t total = 0;
  auto newest_mesh = m_events.end();
  for (auto it = m_events.begin(); it != m_events.end(); ++it) {
    total += mesh_bytes(*it);
    if (it->has_mesh()) newest_mesh = it;
  }
  for (auto it = m_events.begin(); total > MAX_PENDING_MESH_BYTES && it != newest_mesh; ++it) {
    if (!it->has_mesh()) continue;
    const std::size_t triangle_bytes = 4u * static_cast<std::size_t>(it->mesh().triangles_size());
    total -= mesh_bytes(*it);
    strip_mesh_locked(it);
    if (m_sent_connectivity) total += triangle_bytes;  // they moved on to a later queued mesh
  }
  // Then the count: drop the oldest progress-only events (never state changes, never the newest event).
  for (auto it = m_events.begin(); m_events.size() > MAX_PENDING && it != m_events.end();) {
    if (is_progress_only(*it) && std::next(it) != m_events.end()) {
      if (it->has_mesh()) strip_mesh_locked(it);
      it = m_events.erase(it);
      ++m_dropped;
    } else {
      ++it;
    }
  }
}

void WatchChannel::close(std::optional<balloon::v1::JobEvent> last_event, ServiceStatus status) {
  {
    std::lock_guard lock(m_mutex);
    if (m_closed) return;
    if (last_event) m_events.push_back(std::move(*last_event));
    m_closed = true;
    m_status = std::move(status);
  }
  notify();
}

std::optional<balloon::v1::JobEvent> WatchChannel::pop() {
  std::lock_guard lock(m_mutex);
  if (m_events.empty()) return std::nullopt;
  balloon::v1::JobEvent event = std::move(m_events.front());
  m_events.pop_front();
  return event;
}

bool WatchChannel::finished() const {
  std::lock_guard lock(m_mutex);
  return m_closed && m_events.empty();
}

ServiceStatus WatchChannel::final_status() const {
  std::lock_guard lock(m_mutex);
  return m_status;
}

std::uint64_t WatchChannel::dropped() const {
  std::lock_guard lock(m_mutex);
  return m_dropped;
}

std::uint64_t WatchChannel::dropped_meshes() const {
  std::lock_guard lock(m_mutex);
  return m_dropped_meshes;
}

void WatchChannel::set_notifier(std::function<void()> notifier) {
  std::lock_guard lock(m_notifier_mutex);
  m_notifier = std::move(notifier);
}

void WatchChannel::notify() {
  std::lock_guard lock(m_notifier_mutex);
  if (m_notifier) m_notifier();
}

}  // namespace balloon::service
