#pragma once
/// The service's SQLite file: one connection, migrated to the current schema, shared by JobStore and
/// MaterialStore under one mutex (SQLite serializes writers anyway; one connection keeps ":memory:"
/// stores working and the locking simple).
///
/// Durability without holding the lock across an fsync: the connection commits with synchronous=NORMAL
/// (a commit reaches the WAL file but is not flushed, so a process crash loses nothing), and a write that
/// must survive power loss (a submitted job, a result, a state change) calls sync() after releasing the
/// mutex: one fdatasync of the WAL, which concurrent callers share. Checkpoints (copying the WAL into the
/// database, with their own fsyncs) run on a second connection on a background thread, never under the
/// mutex. Progress rows and design checkpoints are not synced: a power loss may lose the last of them.
/// A command's store (not durable) keeps its WAL at close, for the next command to read back, unless the
/// WAL has grown past a few MB: then it is copied into the database and emptied at close.
#include <sys/types.h>

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>

#include "store/database.hpp"

namespace balloon::store {

/// Current wall-clock time in ms since the Unix epoch (the store's timestamps).
std::int64_t now_ms();

struct StoreOptions {
  /// true: sync() makes commits durable across power loss (balloon-server). false: commits survive a
  /// process crash only (the CLI's embedded store: no fsync on the path of a command).
  bool durable = true;
};

class Store {
 public:
  /// Opens or creates the database at `path` (":memory:" for a private one) and migrates it.
  /// Throws DatabaseError if it cannot.
  explicit Store(const std::string& path, StoreOptions options = {});
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  /// The connection, to be used only while holding mutex().
  Database& database() { return m_database; }
  std::mutex& mutex() { return m_mutex; }
  const std::string& path() const { return m_database.path(); }

  /// Makes every commit so far durable (a durable store; a no-op otherwise). Call it WITHOUT holding
  /// mutex(). Also wakes the checkpointer when the WAL has grown.
  void sync();
  /// Runs `write` under mutex(), then sync()s after releasing it; returns what `write` returns.
  template <class Write>
  auto write_durably(Write&& write) {
    std::unique_lock lock(m_mutex);
    if constexpr (std::is_void_v<decltype(write())>) {
      write();
      lock.unlock();
      sync();
    } else {
      auto result = write();
      lock.unlock();
      sync();
      return result;
    }
  }

 private:
  void checkpoint_loop();
  /// The WAL file's size in bytes; -1 without one or when it cannot be read.
  off_t wal_bytes() const;

  StoreOptions m_options;
  Database m_database;
  std::mutex m_mutex;
  int m_wal_fd = -1;  ///< the WAL file, for fdatasync (-1: in memory)

  // Group commit: one fdatasync covers every commit made before it started, so callers that arrive while
  // one runs share the next instead of queueing one each.
  std::mutex m_sync_mutex;
  std::condition_variable m_sync_done;
  std::uint64_t m_sync_requested = 0;  ///< callers so far (each after its commit)
  std::uint64_t m_sync_covered = 0;    ///< callers whose commits the last finished fdatasync covered
  bool m_syncing = false;

  std::unique_ptr<Database> m_checkpoint_database;  ///< the checkpointer's own connection
  std::thread m_checkpointer;
  std::mutex m_checkpoint_mutex;
  std::condition_variable m_checkpoint_wake;
  bool m_checkpoint_due = false;
  bool m_stopping = false;
};

}  // namespace balloon::store
