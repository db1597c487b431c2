#include "store/store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>

#include "store/schema.hpp"

namespace balloon::store {
namespace {

/// The WAL is copied into the database once it holds this many pages since it last started over (as the
/// commits count them, Database::wal_frames), by the checkpointer rather than by whichever commit crosses
/// the line. The WAL file's size is no guide to that once it has grown: a checkpoint starts the log over
/// without shrinking the file, so every durable write woke the checkpointer (246 checkpoints, each with two
/// fsyncs, in bench_service's 2.5 s). A tenth of SQLite's default of 1,000: each checkpoint's flush of the
/// database competes with the submits' fdatasync, and a smaller one holds it up less (bench_service, 24
/// runs each: SubmitJob p99 with every worker busy under 5 ms in 20 runs at 100 pages, 17 at 1,000).
constexpr int CHECKPOINT_WAL_PAGES = 100;
/// A command's store copies its WAL in at close once it holds this much (bytes; its WAL never starts over,
/// since no checkpoint runs while commands do, so the file's size is the measure there).
constexpr off_t CHECKPOINT_WAL_BYTES = 4 << 20;
/// The checkpointer also looks at the WAL this often when nothing wakes it.
constexpr std::chrono::seconds CHECKPOINT_PERIOD{5};

bool in_memory(const std::string& path) { return path.empty() || path == ":memory:"; }

}  // namespace

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

Store::Store(const std::string& path, StoreOptions options)
    : m_options(options), m_database(path, 5000, Synchronous::Normal) {
  migrate(m_database);
  if (in_memory(path)) return;
  // Commits never checkpoint inline (that would fsync the database under the mutex): the checkpointer does.
  m_database.execute("PRAGMA wal_autocheckpoint = 0; PRAGMA journal_size_limit = 67108864");
  m_wal_fd = ::open((path + "-wal").c_str(), O_RDONLY | O_CLOEXEC);
  if (m_wal_fd < 0) {
    // No WAL file to sync (an unusual file system): fall back to a flush at every commit.
    m_database.execute("PRAGMA synchronous = FULL; PRAGMA wal_autocheckpoint = 1000");
    return;
  }
  if (!m_options.durable) {
    // A short-lived command: closing must not checkpoint (fsyncs at every exit, and a new WAL whose
    // header and folder are synced at the next start). The WAL is read back at the next open instead;
    // the command that grows it past CHECKPOINT_WAL_BYTES copies it into the database when it closes.
    m_database.keep_wal_on_close();
    return;
  }
  m_database.count_wal_frames();
  m_checkpoint_database = std::make_unique<Database>(path, 5000, Synchronous::Normal);
  m_checkpointer = std::thread([this] { checkpoint_loop(); });
}

Store::~Store() {
  if (m_checkpointer.joinable()) {
    {
      std::lock_guard lock(m_checkpoint_mutex);
      m_stopping = true;
    }
    m_checkpoint_wake.notify_all();
    // A checkpoint under way stops where it is (what it copied stays copied): closing does not wait for it.
    m_checkpoint_database->interrupt();
    m_checkpointer.join();
    m_checkpoint_database.reset();
  } else if (wal_bytes() >= CHECKPOINT_WAL_BYTES) {
    // A command's store whose WAL has grown: copied in and emptied here, once the command's work is done.
    // A passive checkpoint in the background of such short commands never finished (each open reads the
    // WAL back and starts over), so the WAL grew by every command's writes: 19 MB over 30 small jobs.
    try {
      m_database.execute("PRAGMA wal_checkpoint(TRUNCATE)");
    } catch (const DatabaseError&) {
      // Another command is reading: a later one copies it.
    }
  }
  if (m_wal_fd >= 0) ::close(m_wal_fd);
}

void Store::sync() {
  // Not durable (a command's store): no flush, and no checkpoint during the command either (its fsyncs
  // would compete with the work); what the WAL holds is copied when a later command opens the store.
  if (m_wal_fd < 0 || !m_options.durable) return;
  {
    std::unique_lock lock(m_sync_mutex);
    const std::uint64_t mine = ++m_sync_requested;
    while (m_sync_covered < mine) {
      if (m_syncing) {
        m_sync_done.wait(lock);  // the flush under way may have started before this commit: wait for it
        continue;
      }
      m_syncing = true;  // lead the next flush: it covers every caller so far
      const std::uint64_t covers = m_sync_requested;
      lock.unlock();
      ::fdatasync(m_wal_fd);
      lock.lock();
      m_sync_covered = covers;
      m_syncing = false;
      m_sync_done.notify_all();
    }
  }
  if (m_database.wal_frames() >= CHECKPOINT_WAL_PAGES) {
    {
      std::lock_guard lock(m_checkpoint_mutex);
      m_checkpoint_due = true;
    }
    m_checkpoint_wake.notify_one();
  }
}

off_t Store::wal_bytes() const {
  struct stat info {};
  return m_wal_fd >= 0 && ::fstat(m_wal_fd, &info) == 0 ? info.st_size : -1;
}

void Store::checkpoint_loop() {
  std::unique_lock lock(m_checkpoint_mutex);
  while (!m_stopping) {
    m_checkpoint_wake.wait_for(lock, CHECKPOINT_PERIOD, [this] { return m_stopping || m_checkpoint_due; });
    if (m_stopping) break;
    m_checkpoint_due = false;
    if (wal_bytes() <= 0) continue;
    lock.unlock();
    try {
      // PASSIVE: copies what no reader still needs, without blocking the writer or the readers.
      m_checkpoint_database->execute("PRAGMA wal_checkpoint(PASSIVE)");
    } catch (const DatabaseError&) {
      // Busy or failing: the next round tries again; the WAL only grows meanwhile.
    }
    lock.lock();
  }
}

}  // namespace balloon::store
