#include "service/request_claims.hpp"

namespace balloon::service {

RequestClaims::Claim::Claim(RequestClaims& owner, Key key) : m_key(std::move(key)) {
  if (m_key.second.empty()) return;
  std::unique_lock lock(owner.m_mutex);
  owner.m_released.wait(lock, [&] { return owner.m_in_flight.count(m_key) == 0; });
  owner.m_in_flight.insert(m_key);
  m_owner = &owner;
}

RequestClaims::Claim::~Claim() {
  if (m_owner == nullptr) return;
  {
    std::lock_guard lock(m_owner->m_mutex);
    m_owner->m_in_flight.erase(m_key);
  }
  m_owner->m_released.notify_all();
}

}  // namespace balloon::service
