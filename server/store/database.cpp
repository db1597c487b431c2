#include "store/database.hpp"

#include <sqlite3.h>

namespace balloon::store {
namespace {

/// Distinct SQL texts a connection keeps prepared.
constexpr size_t MAX_CACHED_STATEMENTS = 128;

[[noreturn]] void throw_error(sqlite3* db, const std::string& what) {
  throw DatabaseError(what + ": " + (db != nullptr ? sqlite3_errmsg(db) : "out of memory"));
}

}  // namespace

Database::Database(const std::string& path, int busy_timeout_ms, Synchronous synchronous) : m_path(path) {
  const int flags = SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX;
  if (sqlite3_open_v2(path.c_str(), &m_db, flags, nullptr) != SQLITE_OK) {
    const std::string message = m_db != nullptr ? sqlite3_errmsg(m_db) : "out of memory";
    sqlite3_close(m_db);
    m_db = nullptr;
    throw DatabaseError("cannot open database '" + path + "': " + message);
  }
  sqlite3_extended_result_codes(m_db, 1);
  sqlite3_busy_timeout(m_db, busy_timeout_ms);
  // WAL lets readers proceed during a write. synchronous=FULL makes every commit durable across power
  // loss; NORMAL leaves the flush to the owner (Store::sync), so it need not happen under a lock.
  if (path != ":memory:") execute("PRAGMA journal_mode = WAL");
  execute(synchronous == Synchronous::Full ? "PRAGMA synchronous = FULL; PRAGMA foreign_keys = ON"
                                           : "PRAGMA synchronous = NORMAL; PRAGMA foreign_keys = ON");
  // A row that INSERT OR REPLACE replaces fires its delete triggers only with this on (the store's usage
  // counts rely on them; see schema.cpp, version 6).
  execute("PRAGMA recursive_triggers = ON");
  // Statement journals and sorts in memory: a result's multi-MB blobs must not be copied to /var/tmp.
  execute("PRAGMA temp_store = MEMORY");
}

Database::~Database() {
  // Every Statement is back in the cache or finalized by now (they cannot outlive a Database in our
  // code), so close succeeds once the cache is emptied; close_v2 would defer otherwise rather than leak.
  for (auto& [sql, statement] : m_idle_statements) sqlite3_finalize(statement);
  sqlite3_close_v2(m_db);
}

void Database::count_wal_frames() {
  sqlite3_wal_hook(
      m_db,
      [](void* self, sqlite3*, const char*, int frames) {
        static_cast<Database*>(self)->m_wal_frames.store(frames, std::memory_order_relaxed);
        return SQLITE_OK;
      },
      this);
}

void Database::execute(std::string_view sql) {
  char* message = nullptr;
  const std::string text(sql);
  if (sqlite3_exec(m_db, text.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string error = message != nullptr ? message : "unknown error";
    sqlite3_free(message);
    throw DatabaseError("executing '" + text.substr(0, 60) + "': " + error);
  }
}

Statement Database::prepare(std::string_view sql) {
  std::string key(sql);
  if (const auto idle = m_idle_statements.find(key); idle != m_idle_statements.end()) {
    sqlite3_stmt* statement = idle->second;
    m_idle_statements.erase(idle);
    return Statement(*this, statement, std::move(key));
  }
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v3(m_db, sql.data(), static_cast<int>(sql.size()), SQLITE_PREPARE_PERSISTENT, &statement,
                         nullptr) != SQLITE_OK)
    throw_error(m_db, "preparing '" + std::string(sql.substr(0, 60)) + "'");
  // The store's SQL is a fixed set of texts; beyond this many distinct ones, something builds them.
  if (m_idle_statements.size() >= MAX_CACHED_STATEMENTS) key.clear();
  return Statement(*this, statement, std::move(key));
}

void Database::return_to_cache(std::string sql, sqlite3_stmt* statement) {
  sqlite3_reset(statement);
  sqlite3_clear_bindings(statement);
  if (!m_idle_statements.emplace(std::move(sql), statement).second) sqlite3_finalize(statement);
}

void Database::interrupt() { sqlite3_interrupt(m_db); }

void Database::keep_wal_on_close() {
  sqlite3_db_config(m_db, SQLITE_DBCONFIG_NO_CKPT_ON_CLOSE, 1, nullptr);
}

std::int64_t Database::last_insert_id() const { return sqlite3_last_insert_rowid(m_db); }
int Database::changes() const { return sqlite3_changes(m_db); }

Statement::Statement(Statement&& other) noexcept
    : m_database(other.m_database), m_statement(other.m_statement), m_cache_key(std::move(other.m_cache_key)) {
  other.m_statement = nullptr;
  other.m_cache_key.clear();
}

Statement::~Statement() {
  if (m_statement == nullptr) return;
  if (m_cache_key.empty()) {
    sqlite3_finalize(m_statement);
    return;
  }
  try {
    m_database->return_to_cache(std::move(m_cache_key), m_statement);
  } catch (...) {
    sqlite3_finalize(m_statement);  // out of memory for the cache entry: a destructor must not throw
  }
}

Statement& Statement::bind(int index, std::int64_t value) {
  if (sqlite3_bind_int64(m_statement, index, value) != SQLITE_OK) throw_error(m_database->m_db, "bind");
  return *this;
}

Statement& Statement::bind(int index, double value) {
  if (sqlite3_bind_double(m_statement, index, value) != SQLITE_OK) throw_error(m_database->m_db, "bind");
  return *this;
}

Statement& Statement::bind(int index, std::string_view text) {
  if (sqlite3_bind_text64(m_statement, index, text.data(), text.size(), SQLITE_TRANSIENT, SQLITE_UTF8) != SQLITE_OK)
    throw_error(m_database->m_db, "bind");
  return *this;
}

Statement& Statement::bind_blob(int index, std::string_view bytes) {
  // A zero-length blob must still be a blob, not NULL: pass a non-null pointer.
  static const char empty = 0;
  const char* data = bytes.empty() ? &empty : bytes.data();
  if (sqlite3_bind_blob64(m_statement, index, data, bytes.size(), SQLITE_TRANSIENT) != SQLITE_OK)
    throw_error(m_database->m_db, "bind");
  return *this;
}

Statement& Statement::bind_null(int index) {
  if (sqlite3_bind_null(m_statement, index) != SQLITE_OK) throw_error(m_database->m_db, "bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(m_statement);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  throw_error(m_database->m_db, "step");
}

void Statement::run() {
  while (step()) {
  }
}

void Statement::reset() {
  sqlite3_reset(m_statement);
  sqlite3_clear_bindings(m_statement);
}

std::int64_t Statement::column_int64(int column) const { return sqlite3_column_int64(m_statement, column); }
double Statement::column_double(int column) const { return sqlite3_column_double(m_statement, column); }

std::string Statement::column_text(int column) const {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(m_statement, column));
  if (text == nullptr) return {};
  return std::string(text, static_cast<std::size_t>(sqlite3_column_bytes(m_statement, column)));
}

std::string Statement::column_blob(int column) const {
  const auto* data = static_cast<const char*>(sqlite3_column_blob(m_statement, column));
  if (data == nullptr) return {};
  return std::string(data, static_cast<std::size_t>(sqlite3_column_bytes(m_statement, column)));
}

bool Statement::column_is_null(int column) const {
  return sqlite3_column_type(m_statement, column) == SQLITE_NULL;
}

Transaction::Transaction(Database& database) : m_database(database) { m_database.prepare("BEGIN IMMEDIATE").run(); }

Transaction::~Transaction() {
  if (m_done) return;
  try {
    m_database.prepare("ROLLBACK").run();
  } catch (...) {
    // A failed rollback leaves SQLite to roll back on close; a destructor must not throw.
  }
}

void Transaction::commit() {
  m_database.prepare("COMMIT").run();
  m_done = true;
}

}  // namespace balloon::store
