#include "service/job_queue.hpp"

#include <vector>

namespace balloon::service {

JobQueue::Reservation JobQueue::reserve(const std::string& tenant) {
  std::lock_guard lock(m_mutex);
  if (m_closed || m_queued + m_reserved >= m_capacity) return Reservation::QueueFull;
  Tenant& entry = m_tenants[tenant];
  if (m_max_queued_per_tenant > 0 &&
      entry.entries.size() + entry.reserved >= static_cast<std::size_t>(m_max_queued_per_tenant)) {
    forget_if_idle_locked(m_tenants.find(tenant));
    return Reservation::TenantFull;
  }
  ++entry.reserved;
  ++m_reserved;
  return Reservation::Reserved;
}

void JobQueue::release_reservation(const std::string& tenant) {
  std::lock_guard lock(m_mutex);
  const auto it = m_tenants.find(tenant);
  if (it == m_tenants.end() || it->second.reserved == 0) return;
  --it->second.reserved;
  --m_reserved;
  forget_if_idle_locked(it);
}

void JobQueue::push_locked(std::int64_t row_id, const std::string& tenant, int priority) {
  if (m_closed) return;
  m_tenants[tenant].entries.insert(Entry{priority, m_next_sequence++, row_id});
  ++m_queued;
  m_ready.notify_all();
}

void JobQueue::push_reserved(std::int64_t row_id, const std::string& tenant, int priority) {
  std::lock_guard lock(m_mutex);
  if (const auto it = m_tenants.find(tenant); it != m_tenants.end() && it->second.reserved > 0) {
    --it->second.reserved;
    --m_reserved;
  }
  push_locked(row_id, tenant, priority);
}

void JobQueue::push_recovered(std::int64_t row_id, const std::string& tenant, int priority) {
  std::lock_guard lock(m_mutex);
  push_locked(row_id, tenant, priority);
}

std::map<std::string, JobQueue::Tenant>::iterator JobQueue::next_tenant_locked() {
  const auto may_run = [this](const Tenant& tenant) {
    return !tenant.entries.empty() && (m_max_running_per_tenant <= 0 || tenant.running < m_max_running_per_tenant);
  };
  // The first tenant after the last one served, wrapping around.
  for (auto it = m_tenants.upper_bound(m_last_served); it != m_tenants.end(); ++it)
    if (may_run(it->second)) return it;
  for (auto it = m_tenants.begin(); it != m_tenants.end() && it->first <= m_last_served; ++it)
    if (may_run(it->second)) return it;
  return m_tenants.end();
}

void JobQueue::forget_if_idle_locked(std::map<std::string, Tenant>::iterator tenant) {
  if (tenant != m_tenants.end() && tenant->second.entries.empty() && tenant->second.reserved == 0 &&
      tenant->second.running == 0)
    m_tenants.erase(tenant);
}

std::optional<JobQueue::Popped> JobQueue::pop() {
  std::unique_lock lock(m_mutex);
  auto tenant = m_tenants.end();
  m_ready.wait(lock, [&] {
    if (m_closed) return true;
    tenant = next_tenant_locked();
    return tenant != m_tenants.end();
  });
  if (m_closed) return std::nullopt;
  const Entry entry = *tenant->second.entries.begin();
  tenant->second.entries.erase(tenant->second.entries.begin());
  --m_queued;
  ++tenant->second.running;
  m_last_served = tenant->first;
  return Popped{entry.row_id, tenant->first};
}

void JobQueue::done(const std::string& tenant) {
  std::lock_guard lock(m_mutex);
  const auto it = m_tenants.find(tenant);
  if (it == m_tenants.end() || it->second.running == 0) return;
  --it->second.running;
  forget_if_idle_locked(it);
  m_ready.notify_all();  // the tenant may run its next job now
}

bool JobQueue::remove(std::int64_t row_id) {
  std::lock_guard lock(m_mutex);
  for (auto tenant = m_tenants.begin(); tenant != m_tenants.end(); ++tenant) {
    for (auto it = tenant->second.entries.begin(); it != tenant->second.entries.end(); ++it) {
      if (it->row_id == row_id) {
        tenant->second.entries.erase(it);
        --m_queued;
        forget_if_idle_locked(tenant);
        return true;
      }
    }
  }
  return false;
}

int JobQueue::position(std::int64_t row_id) const {
  std::lock_guard lock(m_mutex);
  // Replays the round-robin from the cursor: each turn takes one job from the next tenant that has one.
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> order;
  for (const auto& [name, tenant] : m_tenants) {
    std::vector<std::int64_t> rows;
    for (const Entry& entry : tenant.entries) rows.push_back(entry.row_id);
    if (!rows.empty()) order.emplace_back(name, std::move(rows));
  }
  std::size_t start = 0;
  while (start < order.size() && order[start].first <= m_last_served) ++start;
  int position = 0;
  for (std::size_t round = 0;; ++round) {
    bool any = false;
    for (std::size_t k = 0; k < order.size(); ++k) {
      const auto& rows = order[(start + k) % order.size()].second;
      if (round >= rows.size()) continue;
      any = true;
      if (rows[round] == row_id) return position;
      ++position;
    }
    if (!any) return -1;
  }
}

std::size_t JobQueue::size() const {
  std::lock_guard lock(m_mutex);
  return m_queued;
}

std::size_t JobQueue::queued(const std::string& tenant) const {
  std::lock_guard lock(m_mutex);
  const auto it = m_tenants.find(tenant);
  return it == m_tenants.end() ? 0 : it->second.entries.size() + it->second.reserved;
}

void JobQueue::close() {
  std::lock_guard lock(m_mutex);
  m_closed = true;
  m_ready.notify_all();
}

}  // namespace balloon::service
