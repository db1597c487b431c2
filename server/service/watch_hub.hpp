#pragma once
/// Who watches which job: the watch channels of every job, the triangles their first intermediate mesh
/// carries, and the per-tenant count of open watch streams. Workers publish here; streams read their own
/// channel. Knows nothing of gRPC.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "balloon/v1/balloon.pb.h"
#include "mesh/tri_mesh.hpp"
#include "service/service_status.hpp"
#include "service/watch_channel.hpp"

namespace balloon::service {

class WatchHub {
 public:
  /// Queues a new channel's first events. Runs under the hub's lock, so no event published meanwhile comes
  /// before them or is lost. Sets *subscribe when the job is unfinished (the channel then receives its
  /// events); otherwise it closes the channel itself. An error refuses the watch.
  using FirstEvents = std::function<ServiceStatus(WatchChannel& channel, bool* subscribe)>;

  /// Opens a watch of `job_id` for `tenant`, who may hold at most `max_per_tenant` open watches (0: no
  /// limit; RESOURCE_EXHAUSTED naming the quota beyond it).
  ServiceStatus open(const std::string& job_id, const std::string& tenant, int max_per_tenant,
                     const FirstEvents& first, std::shared_ptr<WatchChannel>* channel);
  /// The stream of `channel` ended: it stops receiving events and no longer counts for its tenant.
  void close(const std::shared_ptr<WatchChannel>& channel);

  /// The triangles of the job's mesh, sent with each watcher's first intermediate mesh.
  void set_connectivity(const std::string& job_id, const Faces& faces);
  /// Queues `event` on every channel of the job.
  void publish(const std::string& job_id, const balloon::v1::JobEvent& event);
  /// The job finished: queues `last_event` on its channels and closes them (status OK).
  void finish(const std::string& job_id, const balloon::v1::JobEvent& last_event);
  /// Closes every channel with `status` (shutdown).
  void close_all(const ServiceStatus& status);

  /// Open watch streams of `tenant`.
  int open_count(const std::string& tenant) const;

 private:
  mutable std::mutex m_mutex;
  std::multimap<std::string, std::shared_ptr<WatchChannel>> m_watchers;  // job id -> subscribed channels
  std::map<std::string, std::shared_ptr<const std::vector<std::uint32_t>>> m_connectivity;
  std::map<const WatchChannel*, std::string> m_open;  // every open stream's channel -> its tenant
  std::map<std::string, int> m_open_per_tenant;
};

}  // namespace balloon::service
