#include "service/watch_hub.hpp"

namespace balloon::service {

namespace v1 = balloon::v1;

ServiceStatus WatchHub::open(const std::string& job_id, const std::string& tenant, int max_per_tenant,
                             const FirstEvents& first, std::shared_ptr<WatchChannel>* channel) {
  auto opened = std::make_shared<WatchChannel>();
  std::lock_guard lock(m_mutex);
  int& count = m_open_per_tenant[tenant];
  if (max_per_tenant > 0 && count >= max_per_tenant) {
    if (count == 0) m_open_per_tenant.erase(tenant);
    return ServiceStatus::error(StatusCode::ResourceExhausted,
                                "quota max-watches-per-tenant: " + std::to_string(count) +
                                    " watch streams are open, the limit is " + std::to_string(max_per_tenant) +
                                    "; close one first");
  }
  bool subscribe = false;
  const ServiceStatus status = first(*opened, &subscribe);
  if (!status.ok()) {
    if (count == 0) m_open_per_tenant.erase(tenant);
    return status;
  }
  ++count;
  m_open[opened.get()] = tenant;
  if (subscribe) m_watchers.emplace(job_id, opened);
  *channel = std::move(opened);
  return ServiceStatus::success();
}

void WatchHub::close(const std::shared_ptr<WatchChannel>& channel) {
  std::lock_guard lock(m_mutex);
  for (auto it = m_watchers.begin(); it != m_watchers.end();) {
    if (it->second == channel)
      it = m_watchers.erase(it);
    else
      ++it;
  }
  if (const auto it = m_open.find(channel.get()); it != m_open.end()) {
    if (--m_open_per_tenant[it->second] <= 0) m_open_per_tenant.erase(it->second);
    m_open.erase(it);
  }
}

void WatchHub::set_connectivity(const std::string& job_id, const Faces& faces) {
  auto triangles = std::make_shared<std::vector<std::uint32_t>>();
  triangles->reserve(static_cast<std::size_t>(faces.size()));
  for (Eigen::Index i = 0; i < faces.size(); ++i) triangles->push_back(static_cast<std::uint32_t>(faces.data()[i]));
  std::lock_guard lock(m_mutex);
  m_connectivity[job_id] = std::move(triangles);
}

void WatchHub::publish(const std::string& job_id, const v1::JobEvent& event) {
  std::vector<std::shared_ptr<WatchChannel>> channels;
  std::shared_ptr<const std::vector<std::uint32_t>> triangles;
  {
    std::lock_guard lock(m_mutex);
    const auto range = m_watchers.equal_range(job_id);
    for (auto it = range.first; it != range.second; ++it) channels.push_back(it->second);
    if (const auto it = m_connectivity.find(job_id); it != m_connectivity.end()) triangles = it->second;
  }
  for (const auto& channel : channels) channel->push(event, triangles);
}

void WatchHub::finish(const std::string& job_id, const v1::JobEvent& last_event) {
  std::vector<std::shared_ptr<WatchChannel>> channels;
  {
    std::lock_guard lock(m_mutex);
    const auto range = m_watchers.equal_range(job_id);
    for (auto it = range.first; it != range.second; ++it) channels.push_back(it->second);
    m_watchers.erase(range.first, range.second);
    m_connectivity.erase(job_id);
  }
  for (const auto& channel : channels) channel->close(last_event, ServiceStatus::success());
}

void WatchHub::close_all(const ServiceStatus& status) {
  std::vector<std::shared_ptr<WatchChannel>> channels;
  {
    std::lock_guard lock(m_mutex);
    for (auto& [job_id, channel] : m_watchers) channels.push_back(channel);
    m_watchers.clear();
    m_connectivity.clear();
  }
  for (const auto& channel : channels) channel->close(std::nullopt, status);
}

int WatchHub::open_count(const std::string& tenant) const {
  std::lock_guard lock(m_mutex);
  const auto it = m_open_per_tenant.find(tenant);
  return it == m_open_per_tenant.end() ? 0 : it->second;
}

}  // namespace balloon::service
