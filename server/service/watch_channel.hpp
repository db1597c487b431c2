#pragma once
/// One watcher's queue of job events, between the worker that publishes them and the stream that sends
/// them. Knows nothing of gRPC: the stream registers a notifier and pulls events one at a time, so one
/// slow watcher never blocks a worker. Bounded: a watcher that does not read loses intermediate meshes
/// first (the oldest, keeping their progress numbers), then old progress-only events, never a state
/// change; the newest mesh always stays, and the triangles move on to the next mesh it receives.
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "service/service_status.hpp"

namespace balloon::service {

class WatchChannel {
 public:
  /// Events waiting beyond this count make the channel drop its oldest progress-only events.
  static constexpr std::size_t MAX_PENDING = 64;
  /// Bytes of intermediate meshes (positions and triangles) waiting beyond this make the channel strip
  /// the mesh from its oldest mesh events (about 2 meshes of 200k vertices).
  static constexpr std::size_t MAX_PENDING_MESH_BYTES = 8u << 20;

  /// Queues an event. A mesh event gets the job's connectivity if this watcher has not had it yet.
  /// Ignored once the channel is closed.
  void push(balloon::v1::JobEvent event, const std::shared_ptr<const std::vector<std::uint32_t>>& triangles);
  /// Queues a last event and closes the channel with `status` (OK for a finished job).
  void close(std::optional<balloon::v1::JobEvent> last_event, ServiceStatus status);

  /// The next event, if any (for the sender).
  std::optional<balloon::v1::JobEvent> pop();
  /// True when closed and drained: the sender should finish with final_status().
  bool finished() const;
  ServiceStatus final_status() const;

  /// Called (without the channel's lock) whenever an event is pushed or the channel closes.
  /// Set to empty before the sender goes away; setting waits for a notification in progress.
  void set_notifier(std::function<void()> notifier);

  /// Events dropped because the watcher was slow.
  std::uint64_t dropped() const;
  /// Intermediate meshes dropped (stripped from their events or dropped with them) because the watcher was slow.
  std::uint64_t dropped_meshes() const;

 private:
  void notify();
  /// Applies the bounds above (m_mutex held).
  void trim_locked();
  /// Removes the mesh of *it; triangles it carried move to the next queued mesh, or to the next pushed one.
  void strip_mesh_locked(std::deque<balloon::v1::JobEvent>::iterator it);

  mutable std::mutex m_mutex;
  std::deque<balloon::v1::JobEvent> m_events;
  bool m_closed = false;
  bool m_sent_connectivity = false;
  ServiceStatus m_status;
  std::uint64_t m_dropped = 0;
  std::uint64_t m_dropped_meshes = 0;

  std::recursive_mutex m_notifier_mutex;  // recursive: a notifier may re-enter through a synchronous callback
  std::function<void()> m_notifier;
};

}  // namespace balloon::service
