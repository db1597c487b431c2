// Unit tests of the job store's lifecycle queries: recovery by the attempts rule, request ids, deletion
// and the bytes a tenant stores. A private ":memory:" store each.
#include <gtest/gtest.h>

#include "store/job_store.hpp"

namespace balloon::store {
namespace {

JobRecord queued_job(JobStore& jobs, const std::string& job_id, const std::string& owner,
                     const std::string& request_id = "") {
  JobRecord job;
  job.job_id = job_id;
  job.owner = owner;
  job.kind = "simulate";
  job.spec = std::string(1000, 's');
  job.created_ms = now_ms();
  job.request_id = request_id;
  jobs.insert(job);
  return job;
}

TEST(JobStore, RecoveryRequeuesRunningJobsAndFailsThoseOutOfAttempts) {
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord once = queued_job(jobs, "j-once", "alice");
  const JobRecord thrice = queued_job(jobs, "j-thrice", "alice");
  const JobRecord waiting = queued_job(jobs, "j-waiting", "bob");
  ASSERT_TRUE(jobs.mark_running(once.row_id));
  for (int start = 0; start < 3; ++start) {
    ASSERT_TRUE(jobs.mark_running(thrice.row_id));  // each start is stored before the work
    if (start < 2) jobs.mark_requeued(thrice.row_id);
  }
  const JobStore::Recovery recovery = jobs.recover_unfinished(3);
  ASSERT_EQ(recovery.crashed.size(), 1u);
  EXPECT_EQ(recovery.crashed[0].job_id, "j-thrice");
  ASSERT_EQ(recovery.queued.size(), 2u);
  EXPECT_EQ(recovery.queued[0].job_id, "j-once");
  EXPECT_EQ(recovery.queued[1].job_id, "j-waiting");
  const auto failed = jobs.find("j-thrice");
  ASSERT_TRUE(failed);
  EXPECT_EQ(failed->state, JobState::Failed);
  EXPECT_EQ(failed->attempts, 3);
  EXPECT_NE(failed->error.find("crashed the server 3 times"), std::string::npos) << failed->error;
  EXPECT_EQ(jobs.find("j-once")->state, JobState::Queued);
  EXPECT_EQ(jobs.find("j-once")->attempts, 1);
  (void)waiting;
}

TEST(JobStore, RequestIdsArePerOwnerAndWithinTheWindow) {
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord first = queued_job(jobs, "j-first", "alice", "req-1");
  queued_job(jobs, "j-bob", "bob", "req-1");
  const auto found = jobs.find_request("alice", "req-1", now_ms() - 1000);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->job_id, "j-first");
  EXPECT_FALSE(jobs.find_request("alice", "req-2", 0));
  EXPECT_FALSE(jobs.find_request("alice", "req-1", first.created_ms + 1)) << "outside the window";
  EXPECT_EQ(jobs.find_request("bob", "req-1", 0)->job_id, "j-bob");
}

TEST(JobStore, OnlyFinishedJobsAreDeletedAndTheirBytesGoWithThem) {
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord done = queued_job(jobs, "j-done", "alice");
  const JobRecord running = queued_job(jobs, "j-running", "alice");
  ASSERT_TRUE(jobs.mark_running(done.row_id));
  ASSERT_TRUE(jobs.mark_running(running.row_id));
  ResultRecord result;
  result.rest_mesh = std::string(5000, 'r');
  result.inflated_mesh = std::string(5000, 'i');
  result.report_json = "{}";
  ASSERT_TRUE(jobs.mark_completed(done.row_id, result));
  const std::int64_t before = jobs.stored_bytes("alice");
  EXPECT_GE(before, 2 * 1000 + 10000);
  EXPECT_EQ(jobs.stored_bytes("bob"), 0);
  EXPECT_FALSE(jobs.delete_finished(running.row_id));
  EXPECT_TRUE(jobs.delete_finished(done.row_id));
  EXPECT_FALSE(jobs.find("j-done"));
  EXPECT_FALSE(jobs.result(done.row_id));
  EXPECT_LE(jobs.stored_bytes("alice"), before - 11000);
  // Retention: a job that finished before the cutoff goes, a running one stays.
  jobs.mark_failed(running.row_id, "x");
  EXPECT_EQ(jobs.delete_finished_before(now_ms() - 60000), 0);
  EXPECT_EQ(jobs.delete_finished_before(now_ms() + 1), 1);
}

}  // namespace
}  // namespace balloon::store
