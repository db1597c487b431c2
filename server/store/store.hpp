#pragma once
/// The service's SQLite file: one connection, migrated to the current schema, shared by JobStore and
/// MaterialStore under one mutex (SQLite serializes writers anyway; one connection keeps ":memory:"
/// stores working and the locking simple).
#include <memory>
#include <mutex>
#include <string>

#include "store/database.hpp"

namespace balloon::store {

/// Current wall-clock time in ms since the Unix epoch (the store's timestamps).
std::int64_t now_ms();

class Store {
 public:
  /// Opens or creates the database at `path` (":memory:" for a private one) and migrates it.
  /// Throws DatabaseError if it cannot.
  explicit Store(const std::string& path);

  /// The connection, to be used only while holding mutex().
  Database& database() { return m_database; }
  std::mutex& mutex() { return m_mutex; }
  const std::string& path() const { return m_database.path(); }

 private:
  Database m_database;
  std::mutex m_mutex;
};

}  // namespace balloon::store
