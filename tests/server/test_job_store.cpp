// Unit tests of the job store's lifecycle queries: recovery by the attempts rule, request ids, listings by
// state, deletion and the bytes a tenant stores, progress batches, and a command's store reopened from its WAL. A private
// ":memory:" store each, except the reopened one (a temporary file).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "store/database.hpp"
#include "store/job_store.hpp"
#include "store/schema.hpp"

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
  result.report = std::string(300, 'p');
  result.mold_mesh = std::string(2000, 'm');
  ASSERT_TRUE(jobs.mark_completed(done.row_id, result));
  const std::int64_t before = jobs.stored_bytes("alice");
  EXPECT_GE(before, 2 * 1000 + 12300) << "the report and the mold count too";
  EXPECT_EQ(jobs.stored_bytes("bob"), 0);
  EXPECT_FALSE(jobs.delete_finished(running.row_id));
  EXPECT_TRUE(jobs.delete_finished(done.row_id));
  EXPECT_FALSE(jobs.find("j-done"));
  EXPECT_FALSE(jobs.result(done.row_id));
  EXPECT_LE(jobs.stored_bytes("alice"), before - 13300);
  // Retention: a job that finished before the cutoff goes, a running one stays.
  jobs.mark_failed(running.row_id, "x");
  EXPECT_EQ(jobs.delete_finished_before(now_ms() - 60000), 0);
  EXPECT_EQ(jobs.delete_finished_before(now_ms() + 1), 1);
}

// A result keeps its typed report and the mold the server built; a result without a mold reads back none.
TEST(JobStore, ResultsKeepTheirReportAndMold) {
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord design = queued_job(jobs, "j-design", "alice");
  const JobRecord simulate = queued_job(jobs, "j-simulate", "alice");
  ASSERT_TRUE(jobs.mark_running(design.row_id));
  ASSERT_TRUE(jobs.mark_running(simulate.row_id));
  ResultRecord with_mold;
  with_mold.converged = true;
  with_mold.rest_mesh = "rest";
  with_mold.inflated_mesh = "inflated";
  with_mold.report = std::string("\x08\x01\x12\x07matched", 11);  // binary: NUL-free is not assumed
  with_mold.mold_mesh = std::string("mold\0blob", 9);
  ASSERT_TRUE(jobs.mark_completed(design.row_id, with_mold));
  ResultRecord without_mold = with_mold;
  without_mold.mold_mesh.clear();
  ASSERT_TRUE(jobs.mark_completed(simulate.row_id, without_mold));

  const std::optional<ResultRecord> read = jobs.result(design.row_id);
  ASSERT_TRUE(read);
  EXPECT_TRUE(read->converged);
  EXPECT_EQ(read->report, with_mold.report);
  EXPECT_EQ(read->mold_mesh, with_mold.mold_mesh);
  EXPECT_EQ(read->report_json, "") << "new results keep the typed report only";
  const std::optional<ResultRecord> plain = jobs.result(simulate.row_id);
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->mold_mesh, "");
  EXPECT_EQ(plain->report, with_mold.report);
}

TEST(JobStore, AProgressBatchIsOneWriteAndKeepsItsShapeWithItsRow) {
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord job = queued_job(jobs, "j-batch", "alice");
  ASSERT_TRUE(jobs.mark_running(job.row_id));
  std::vector<ProgressRecord> rows(3);
  for (int i = 0; i < 3; ++i) {
    rows[static_cast<std::size_t>(i)].phase = "inflate";
    rows[static_cast<std::size_t>(i)].iteration = i + 1;
    rows[static_cast<std::size_t>(i)].pressure_kpa = 1.5 * (i + 1);
  }
  jobs.append_progress(job.row_id, rows[0], "old shape");
  jobs.append_progress_batch(job.row_id, rows, "new shape", 1);
  EXPECT_EQ(jobs.progress_count(job.row_id), 4);
  EXPECT_EQ(jobs.latest_shape(job.row_id).value_or(""), "new shape") << "a job keeps one stored shape";
  const auto found = jobs.find("j-batch");
  ASSERT_TRUE(found && found->last_progress);
  EXPECT_EQ(found->last_progress->iteration, 3);
  EXPECT_NEAR(found->last_progress->pressure_kpa, 4.5, 1e-12);
  jobs.append_progress_batch(job.row_id, {}, "ignored", 0);
  EXPECT_EQ(jobs.progress_count(job.row_id), 4) << "an empty batch writes nothing";
}

/// One CLI command on the store at `path` (not durable): a job run to a result of 600 kB of meshes.
void command_storing_a_result(const std::string& path, const std::string& job_id) {
  Store store(path, StoreOptions{false});
  JobStore jobs(store);
  JobRecord job = queued_job(jobs, job_id, "alice");
  ResultRecord result;
  result.converged = true;
  result.rest_mesh = std::string(300000, 'r');
  result.inflated_mesh = std::string(300000, 'i');
  ASSERT_TRUE(jobs.mark_running(job.row_id));
  ASSERT_TRUE(jobs.mark_completed(job.row_id, result));
}

void remove_store_files(const std::string& path) {
  for (const char* suffix : {"", "-wal", "-shm"}) std::remove((path + suffix).c_str());
}

TEST(JobStore, ACommandsStoreKeepsItsWalAtCloseAndTheNextOpenReadsIt) {
  // The embedded CLI store neither flushes nor checkpoints at close: what it committed must still be
  // there for the next command (the WAL is read back at open).
  const std::string path = ::testing::TempDir() + "balloon-store-wal-" + std::to_string(::getpid()) + ".db";
  remove_store_files(path);
  command_storing_a_result(path, "j-kept");
  std::FILE* wal = std::fopen((path + "-wal").c_str(), "rb");
  EXPECT_NE(wal, nullptr) << "the WAL was checkpointed and removed at close";
  if (wal) std::fclose(wal);
  {
    Store store(path, StoreOptions{false});
    JobStore jobs(store);
    const auto found = jobs.find("j-kept");
    ASSERT_TRUE(found);
    EXPECT_EQ(found->state, JobState::Completed);
    const auto result = jobs.result(found->row_id);
    ASSERT_TRUE(result);
    EXPECT_EQ(result->inflated_mesh.size(), 300000u);
  }
  remove_store_files(path);
}

TEST(JobStore, ACommandsWalStaysBoundedOverManyCommands) {
  // Commands keep their WAL at close; the one whose writes take it past 4 MB copies it into the database,
  // so a long series of commands does not grow it (and the work of reading it back at every open).
  const std::string path = ::testing::TempDir() + "balloon-store-bounded-" + std::to_string(::getpid()) + ".db";
  remove_store_files(path);
  long largest_wal = 0;
  for (int command = 0; command < 30; ++command) {
    command_storing_a_result(path, "j-" + std::to_string(command));
    if (std::FILE* wal = std::fopen((path + "-wal").c_str(), "rb")) {
      std::fseek(wal, 0, SEEK_END);
      largest_wal = std::max(largest_wal, std::ftell(wal));
      std::fclose(wal);
    }
  }
  // 30 commands wrote about 18 MB; the WAL never holds more than the threshold and one command's writes.
  EXPECT_LT(largest_wal, 6L << 20);
  Store store(path, StoreOptions{false});
  JobStore jobs(store);
  for (int command = 0; command < 30; ++command) EXPECT_TRUE(jobs.find("j-" + std::to_string(command)));
  remove_store_files(path);
}

TEST(JobStore, ASpecIsReadOnlyWhenAskedForAndGoesWithItsJob) {
  // The spec holds the uploaded mesh: lookups and state changes leave it alone; the runner asks for it.
  Store store(":memory:");
  JobStore jobs(store);
  const JobRecord job = queued_job(jobs, "j-spec", "alice");
  ASSERT_TRUE(jobs.mark_running(job.row_id));
  const auto found = jobs.find("j-spec");
  ASSERT_TRUE(found);
  EXPECT_TRUE(found->spec.empty()) << "a lookup does not read the spec";
  EXPECT_EQ(jobs.spec(job.row_id), std::string(1000, 's'));
  EXPECT_GE(jobs.stored_bytes("alice"), 1000) << "the spec counts towards the owner's bytes";
  jobs.mark_failed(job.row_id, "x");
  ASSERT_TRUE(jobs.delete_finished(job.row_id));
  EXPECT_FALSE(jobs.spec(job.row_id));
  EXPECT_EQ(jobs.stored_bytes("alice"), 0);
}

TEST(JobStore, AJobQueuedBeforeSpecsMovedToTheirOwnTableKeepsItsSpec) {
  // A store written by a build of schema version 4 (the spec in the jobs row), opened by this one.
  const std::string path = ::testing::TempDir() + "balloon-store-v4-" + std::to_string(::getpid()) + ".db";
  remove_store_files(path);
  {
    Database old_store(path);
    migrate(old_store, 4);
    old_store.execute("INSERT INTO jobs (job_id, owner, kind, state, spec, created_ms) "
                      "VALUES ('j-old', 'alice', 'simulate', 'queued', X'0A0B0C', 1)");
  }
  {
    Store store(path);
    JobStore jobs(store);
    const auto found = jobs.find("j-old");
    ASSERT_TRUE(found);
    EXPECT_EQ(found->state, JobState::Queued);
    EXPECT_EQ(jobs.spec(found->row_id), std::string("\x0A\x0B\x0C"));
    EXPECT_EQ(jobs.recover_unfinished(3).queued.size(), 1u);
    EXPECT_EQ(jobs.stored_bytes("alice"), 3) << "the migration counts what was stored before it";
  }
  remove_store_files(path);
}

/// The bytes `owner` stores, summed over every row (what the usage triggers keep up to date).
std::int64_t recounted_bytes(Database& database, const std::string& owner) {
  Statement statement = database.prepare(
      "SELECT (SELECT COALESCE(SUM(LENGTH(summary) + LENGTH(error)), 0) FROM jobs WHERE owner = ?1) + "
      "(SELECT COALESCE(SUM(LENGTH(s.spec)), 0) FROM job_specs AS s JOIN jobs AS j ON j.id = s.job_row "
      " WHERE j.owner = ?1) + "
      "(SELECT COALESCE(SUM(LENGTH(r.rest_mesh) + LENGTH(r.inflated_mesh) + LENGTH(CAST(r.report_json AS BLOB)) + "
      " COALESCE(LENGTH(r.report), 0) + COALESCE(LENGTH(r.mold_mesh), 0)), 0) "
      " FROM results AS r JOIN jobs AS j ON j.id = r.job_row WHERE j.owner = ?1) + "
      "(SELECT COALESCE(SUM(COALESCE(LENGTH(p.shape), 0) + 64), 0) "
      " FROM progress AS p JOIN jobs AS j ON j.id = p.job_row WHERE j.owner = ?1)");
  statement.bind(1, owner);
  return statement.step() ? statement.column_int64(0) : -1;
}

TEST(JobStore, AListingOfOneStatePagesThroughThatStateOfTheOwnerOnly) {
  Store store(":memory:");
  JobStore jobs(store);
  // alice: jobs 0..9, every third one running; bob: one running job between them.
  std::vector<std::int64_t> alice_running;
  for (int n = 0; n < 10; ++n) {
    const JobRecord job = queued_job(jobs, "j-a" + std::to_string(n), "alice");
    if (n % 3 == 0) {
      ASSERT_TRUE(jobs.mark_running(job.row_id));
      alice_running.push_back(job.row_id);
    }
    if (n == 4) {
      ASSERT_TRUE(jobs.mark_running(queued_job(jobs, "j-b", "bob").row_id));
    }
  }
  std::reverse(alice_running.begin(), alice_running.end());  // newest first

  std::vector<std::int64_t> listed;
  std::int64_t before = 0;
  for (int page = 0; page < 10; ++page) {
    const JobPage running = jobs.list("alice", JobState::Running, before, 3);
    for (const JobRecord& job : running.jobs) {
      EXPECT_EQ(job.owner, "alice");
      EXPECT_EQ(job.state, JobState::Running);
      listed.push_back(job.row_id);
    }
    before = running.next_before_row;
    if (before == 0) break;
  }
  EXPECT_EQ(listed, alice_running);

  const JobPage queued = jobs.list("alice", JobState::Queued, 0, 100);
  EXPECT_EQ(queued.jobs.size(), 6u);
  EXPECT_EQ(queued.next_before_row, 0);
  EXPECT_EQ(jobs.list("alice", std::nullopt, 0, 100).jobs.size(), 10u);
  EXPECT_TRUE(jobs.list("bob", JobState::Queued, 0, 100).jobs.empty());
}

TEST(JobStore, TheBytesATenantStoresFollowEveryWrite) {
  Store store(":memory:");
  JobStore jobs(store);
  const auto expect_counted = [&](const char* after) {
    for (const char* owner : {"alice", "bob"}) {
      std::int64_t recounted = 0;
      {
        std::lock_guard lock(store.mutex());
        recounted = recounted_bytes(store.database(), owner);
      }
      EXPECT_EQ(jobs.stored_bytes(owner), recounted) << owner << ", after " << after;
    }
  };
  JobRecord a = queued_job(jobs, "j-a", "alice");
  JobRecord b = queued_job(jobs, "j-b", "bob");
  JobRecord c = queued_job(jobs, "j-c", "alice");
  expect_counted("inserts");
  ASSERT_TRUE(jobs.mark_running(a.row_id));
  ProgressRecord row;
  row.phase = "design";
  jobs.append_progress(a.row_id, row, std::string(700, 's'));
  jobs.append_progress_batch(a.row_id, {row, row}, std::string(300, 't'), 1);  // clears the older shape
  expect_counted("progress");
  ResultRecord result;
  result.rest_mesh = std::string(5000, 'r');
  result.inflated_mesh = std::string(4000, 'i');
  result.report = std::string(300, 'p');
  result.mold_mesh = std::string(2000, 'm');
  ASSERT_TRUE(jobs.mark_completed(a.row_id, result));
  jobs.mark_failed(b.row_id, "the start could not be inflated");
  ASSERT_TRUE(jobs.mark_cancelled(c.row_id, "cancelled by its owner"));
  expect_counted("results, failures and cancellations");
  {
    // The store writes a result with INSERT OR REPLACE: a replaced one must leave the count too.
    std::lock_guard lock(store.mutex());
    store.database()
        .prepare("INSERT OR REPLACE INTO results (job_row, converged, rest_mesh, inflated_mesh, report_json, "
                 "created_ms) VALUES (?, 1, X'00', X'0000', '{}', 0)")
        .bind(1, a.row_id)
        .run();
  }
  expect_counted("a replaced result");
  EXPECT_TRUE(jobs.delete_finished(a.row_id));
  expect_counted("a deletion");
  EXPECT_EQ(jobs.delete_finished_before(now_ms() + 1), 2);
  expect_counted("the retention sweep");
  EXPECT_EQ(jobs.stored_bytes("alice"), 0);
  EXPECT_EQ(jobs.stored_bytes("bob"), 0);
}

}  // namespace
}  // namespace balloon::store
