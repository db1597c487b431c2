// Unit tests of one watcher's channel: a watcher that does not read loses meshes, never state changes.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "service/watch_channel.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;

v1::JobEvent state_event(v1::JobState state, const std::string& message) {
  v1::JobEvent event;
  event.set_state(state);
  event.set_message(message);
  return event;
}

/// A progress event at `iteration` carrying `vertices` positions.
v1::JobEvent mesh_event(int iteration, int vertices) {
  v1::JobEvent event;
  event.set_state(v1::JOB_STATE_RUNNING);
  event.mutable_progress()->set_iteration(iteration);
  event.mutable_mesh()->set_iteration(iteration);
  event.mutable_mesh()->set_vertex_count(static_cast<std::uint32_t>(vertices));
  event.mutable_mesh()->mutable_positions_mm()->Resize(3 * vertices, 1.0f);
  return event;
}

TEST(WatchChannel, ASlowWatcherLosesMeshesNeverStateChanges) {
  WatchChannel channel;
  const auto triangles = std::make_shared<const std::vector<std::uint32_t>>(6 * 100000, 7u);
  channel.push(state_event(v1::JOB_STATE_RUNNING, "running"), nullptr);
  channel.push(state_event(v1::JOB_STATE_RUNNING, "started (attempt 1)"), nullptr);
  // 300 shape events of 100k vertices (1.2 MB of positions each) while nobody reads.
  for (int i = 0; i < 300; ++i) {
    channel.push(mesh_event(i, 100000), triangles);
    if (i == 150) channel.push(state_event(v1::JOB_STATE_RUNNING, "phase tolerance"), nullptr);
  }
  channel.close(state_event(v1::JOB_STATE_COMPLETED, "completed"), ServiceStatus::success());

  std::vector<v1::JobEvent> events;
  while (auto event = channel.pop()) events.push_back(std::move(*event));
  EXPECT_TRUE(channel.finished());
  std::vector<std::string> messages;
  std::size_t pending_mesh_bytes = 0;
  int meshes = 0, with_triangles = 0, last_mesh_iteration = -1;
  for (const v1::JobEvent& event : events) {
    if (!event.message().empty()) messages.push_back(event.message());
    if (!event.has_mesh()) continue;
    ++meshes;
    with_triangles += event.mesh().triangles_size() > 0 ? 1 : 0;
    pending_mesh_bytes += 4u * static_cast<std::size_t>(event.mesh().positions_mm_size() + event.mesh().triangles_size());
    last_mesh_iteration = static_cast<int>(event.mesh().iteration());
  }
  // Every state change, in order.
  EXPECT_EQ(messages, (std::vector<std::string>{"running", "started (attempt 1)", "phase tolerance", "completed"}));
  EXPECT_LE(events.size(), WatchChannel::MAX_PENDING + 1);
  // Meshes bounded in bytes, the newest kept, and the first mesh the watcher gets carries the triangles.
  EXPECT_GE(meshes, 1);
  EXPECT_LE(pending_mesh_bytes, WatchChannel::MAX_PENDING_MESH_BYTES + 4u * 3 * 100000);
  EXPECT_EQ(last_mesh_iteration, 299);
  EXPECT_EQ(with_triangles, 1);
  for (const v1::JobEvent& event : events) {
    if (!event.has_mesh()) continue;
    EXPECT_EQ(event.mesh().triangles_size(), 6 * 100000) << "the first mesh carries the connectivity";
    break;
  }
  EXPECT_GT(channel.dropped_meshes(), 250u);
}

}  // namespace
}  // namespace balloon::service
