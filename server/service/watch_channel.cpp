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
    // A slow watcher: drop the oldest events that carry only progress (never state changes, never the
    // one carrying the connectivity), so memory stays bounded and the latest state still arrives.
    for (auto it = m_events.begin(); m_events.size() > MAX_PENDING && it != m_events.end();) {
      const bool droppable = it->message().empty() && it->mesh().triangles_size() == 0 && std::next(it) != m_events.end();
      if (droppable) {
        it = m_events.erase(it);
        ++m_dropped;
      } else {
        ++it;
      }
    }
  }
  notify();
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

void WatchChannel::set_notifier(std::function<void()> notifier) {
  std::lock_guard lock(m_notifier_mutex);
  m_notifier = std::move(notifier);
}

void WatchChannel::notify() {
  std::lock_guard lock(m_notifier_mutex);
  if (m_notifier) m_notifier();
}

}  // namespace balloon::service
