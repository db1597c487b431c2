#pragma once
/// The submissions in flight, by (tenant, request_id). A retry of a request that is still being stored
/// waits for the first copy and then finds its job; requests with different ids never wait for each other
/// (one lock across every submission's fsync made concurrent clients queue behind each other's disk writes).
#include <condition_variable>
#include <mutex>
#include <set>
#include <string>
#include <utility>

namespace balloon::service {

class RequestClaims {
 public:
  using Key = std::pair<std::string, std::string>;  ///< (tenant, request_id)

  /// Holds one key until destroyed; an empty request_id claims nothing.
  class Claim {
   public:
    Claim(RequestClaims& owner, Key key);
    ~Claim();
    Claim(const Claim&) = delete;
    Claim& operator=(const Claim&) = delete;

   private:
    RequestClaims* m_owner = nullptr;  // null when nothing was claimed
    Key m_key;
  };

  /// Waits while another submission holds the same key, then holds it.
  Claim claim(const std::string& tenant, const std::string& request_id) { return Claim(*this, {tenant, request_id}); }

 private:
  std::mutex m_mutex;
  std::condition_variable m_released;
  std::set<Key> m_in_flight;
};

}  // namespace balloon::service
