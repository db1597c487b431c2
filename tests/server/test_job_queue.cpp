// Unit tests of the job queue: round-robin between tenants before priority, per-tenant limits.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "service/job_queue.hpp"

namespace balloon::service {
namespace {

std::vector<std::int64_t> pop_all(JobQueue& queue, std::size_t count) {
  std::vector<std::int64_t> rows;
  for (std::size_t i = 0; i < count; ++i) {
    const auto popped = queue.pop();
    if (!popped) break;
    rows.push_back(popped->row_id);
    queue.done(popped->tenant);
  }
  return rows;
}

TEST(JobQueue, TenantsTakeTurnsBeforePriority) {
  JobQueue queue(100);
  // alice queues four jobs (one urgent) before bob queues two and carol one.
  queue.push_recovered(1, "alice", 0);
  queue.push_recovered(2, "alice", 0);
  queue.push_recovered(3, "alice", 100);
  queue.push_recovered(4, "alice", 0);
  queue.push_recovered(11, "bob", 0);
  queue.push_recovered(12, "bob", -5);
  queue.push_recovered(21, "carol", 0);
  EXPECT_EQ(queue.position(3), 0);
  EXPECT_EQ(queue.position(11), 1);
  EXPECT_EQ(queue.position(1), 3);
  EXPECT_EQ(queue.position(99), -1);
  // One job per tenant per turn; within alice, priority then age.
  EXPECT_EQ(pop_all(queue, 7), (std::vector<std::int64_t>{3, 11, 21, 1, 12, 2, 4}));
}

TEST(JobQueue, ATenantAtItsRunningLimitWaitsWhileOthersRun) {
  JobQueue queue(100, 0, 1);
  queue.push_recovered(1, "alice", 0);
  queue.push_recovered(2, "alice", 0);
  queue.push_recovered(11, "bob", 0);
  queue.push_recovered(12, "bob", 0);
  const auto first = queue.pop();   // alice's first
  const auto second = queue.pop();  // bob's first
  ASSERT_TRUE(first && second);
  EXPECT_EQ(first->row_id, 1);
  EXPECT_EQ(second->row_id, 11);
  // alice and bob each have one running: nobody may start until one finishes.
  queue.done("bob");
  const auto third = queue.pop();
  ASSERT_TRUE(third);
  EXPECT_EQ(third->row_id, 12);
  queue.done("alice");
  const auto fourth = queue.pop();
  ASSERT_TRUE(fourth);
  EXPECT_EQ(fourth->row_id, 2);
}

TEST(JobQueue, ReservationsCountAgainstTheQueueAndEachTenant) {
  JobQueue queue(3, 2, 0);
  EXPECT_EQ(queue.reserve("alice"), JobQueue::Reservation::Reserved);
  EXPECT_EQ(queue.reserve("alice"), JobQueue::Reservation::Reserved);
  EXPECT_EQ(queue.reserve("alice"), JobQueue::Reservation::TenantFull);
  EXPECT_EQ(queue.reserve("bob"), JobQueue::Reservation::Reserved);
  EXPECT_EQ(queue.reserve("carol"), JobQueue::Reservation::QueueFull);
  queue.release_reservation("alice");
  queue.push_reserved(1, "alice", 0);
  EXPECT_EQ(queue.queued("alice"), 1u);
  EXPECT_EQ(queue.size(), 1u);
  EXPECT_EQ(queue.reserve("carol"), JobQueue::Reservation::Reserved);
  EXPECT_TRUE(queue.remove(1));
  EXPECT_FALSE(queue.remove(1));
  EXPECT_EQ(queue.queued("alice"), 0u);
}

}  // namespace
}  // namespace balloon::service
