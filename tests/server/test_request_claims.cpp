// Unit tests of the request-id claims: a repeat of a request in flight waits for the first copy, other
// requests never wait (they used to queue behind one lock held across every submission's fsync).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include "service/request_claims.hpp"

namespace balloon::service {
namespace {

using namespace std::chrono_literals;

TEST(RequestClaims, ARepeatOfARequestInFlightWaitsForTheFirstCopy) {
  RequestClaims claims;
  std::atomic<bool> first_released{false};
  std::promise<void> repeat_claimed;
  std::future<void> repeat_done;
  {
    const RequestClaims::Claim first = claims.claim("alice", "id-1");
    repeat_done = std::async(std::launch::async, [&] {
      const RequestClaims::Claim repeat = claims.claim("alice", "id-1");
      EXPECT_TRUE(first_released.load()) << "the repeat went ahead while the first copy was still being stored";
    });
    EXPECT_EQ(repeat_done.wait_for(100ms), std::future_status::timeout);
    first_released = true;
  }
  EXPECT_EQ(repeat_done.wait_for(5s), std::future_status::ready);
}

TEST(RequestClaims, OtherIdsOtherTenantsAndNoIdNeverWait) {
  RequestClaims claims;
  const RequestClaims::Claim held = claims.claim("alice", "id-1");
  auto claim_in_thread = [&](const char* tenant, const char* id) {
    return std::async(std::launch::async, [&claims, tenant, id] { const RequestClaims::Claim other = claims.claim(tenant, id); });
  };
  auto other_id = claim_in_thread("alice", "id-2");
  auto other_tenant = claim_in_thread("bob", "id-1");
  auto no_id = claim_in_thread("alice", "");
  auto no_id_again = claim_in_thread("alice", "");
  EXPECT_EQ(other_id.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(other_tenant.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(no_id.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(no_id_again.wait_for(5s), std::future_status::ready);
}

}  // namespace
}  // namespace balloon::service
