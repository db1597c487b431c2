#pragma once
/// A thin RAII layer over one SQLite connection: the connection, prepared statements and transactions.
/// sqlite3.h stays in database.cpp; errors from SQLite throw DatabaseError (they are not user input).
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

struct sqlite3;
struct sqlite3_stmt;

namespace balloon::store {

/// A failed SQLite call: names the call and carries SQLite's message.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Statement;

/// When a commit is flushed to disk. Full: at every commit (durable on return). Normal: at checkpoints
/// only (a commit survives a process crash; the owner flushes the WAL itself when it needs durability).
enum class Synchronous { Full, Normal };

/// One open connection, in WAL mode with a busy timeout and foreign keys on. Not thread-safe: the owner
/// serializes access (JobStore holds a mutex).
class Database {
 public:
  /// Opens (creating if needed) the database at `path`; ":memory:" for a private in-memory one.
  /// `busy_timeout_ms` is how long a write waits for another connection's lock (ms).
  explicit Database(const std::string& path, int busy_timeout_ms = 5000, Synchronous synchronous = Synchronous::Full);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  /// Runs one or more statements that take no parameters and return no rows (DDL, PRAGMA).
  void execute(std::string_view sql);
  /// A prepared statement for `sql`, from this connection's cache when that text was prepared before:
  /// parsing and planning a query took 0.2 ms, a quarter of a SubmitJob's time in the handler.
  Statement prepare(std::string_view sql);

  /// Row id of the last INSERT on this connection.
  std::int64_t last_insert_id() const;
  /// Rows changed by the last INSERT, UPDATE or DELETE.
  int changes() const;
  /// Leaves the WAL as it is when this connection, the last one, closes (no checkpoint, no fsync at close).
  void keep_wal_on_close();
  /// Makes a statement running on this connection (from another thread) stop soon with an error.
  void interrupt();
  /// From now on, counts the pages (frames) in the WAL after each commit on this connection (SQLite's
  /// WAL hook, which also drives its own automatic checkpoints: those stop; the owner checkpoints).
  void count_wal_frames();
  /// Pages in the WAL after the last commit on this connection (count_wal_frames; 0 before). A checkpoint
  /// that copied the whole WAL lets the next commit start it over, so this falls back then, where the
  /// WAL file's size does not.
  int wal_frames() const { return m_wal_frames.load(std::memory_order_relaxed); }
  /// The path it was opened with.
  const std::string& path() const { return m_path; }

 private:
  friend class Statement;
  /// Takes back a cached statement its Statement no longer uses (reset, bindings cleared).
  void return_to_cache(std::string sql, sqlite3_stmt* statement);

  std::string m_path;
  sqlite3* m_db = nullptr;
  std::atomic<int> m_wal_frames{0};
  /// Prepared statements not in use, by SQL text. A text in use twice at once gets a second, uncached one.
  std::unordered_map<std::string, sqlite3_stmt*> m_idle_statements;
};

/// A prepared statement. Bind with 1-based indices (`?` placeholders), step through rows, read columns
/// with 0-based indices. Finalized on destruction.
class Statement {
 public:
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&&) = delete;
  Statement(const Statement&) = delete;
  ~Statement();

  Statement& bind(int index, std::int64_t value);
  Statement& bind(int index, int value) { return bind(index, static_cast<std::int64_t>(value)); }
  Statement& bind(int index, double value);
  Statement& bind(int index, std::string_view text);
  Statement& bind(int index, const char* text) { return bind(index, std::string_view(text)); }
  Statement& bind_blob(int index, std::string_view bytes);
  Statement& bind_null(int index);

  /// Advances to the next row: true while there is one, false when done.
  bool step();
  /// Runs a statement that returns no rows.
  void run();
  /// Clears bindings and rewinds, to run the statement again.
  void reset();

  std::int64_t column_int64(int column) const;
  int column_int(int column) const { return static_cast<int>(column_int64(column)); }
  double column_double(int column) const;
  std::string column_text(int column) const;
  std::string column_blob(int column) const;
  bool column_is_null(int column) const;

 private:
  friend class Database;
  Statement(Database& database, sqlite3_stmt* statement, std::string cache_key)
      : m_database(&database), m_statement(statement), m_cache_key(std::move(cache_key)) {}
  Database* m_database;
  sqlite3_stmt* m_statement;
  std::string m_cache_key;  ///< the SQL text it goes back to the cache under; empty: finalized instead
};

/// BEGIN IMMEDIATE on construction; rolls back on destruction unless commit() was called.
/// IMMEDIATE takes the write lock up front, so a transaction never fails half-way on a lock upgrade.
class Transaction {
 public:
  explicit Transaction(Database& database);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& m_database;
  bool m_done = false;
};

}  // namespace balloon::store
