#pragma once
/// The store's schema and its migrations. The version lives in PRAGMA user_version; each migration
/// moves it up by one inside a transaction, so a crash mid-migration leaves the previous version.
namespace balloon::store {

class Database;

/// The schema version this build writes.
int current_schema_version();

/// Brings the database up to `target` (current_schema_version() unless a test builds an older store to
/// upgrade). Throws DatabaseError if the file is newer than this build understands (it would not know how
/// to read it).
void migrate(Database& database, int target = current_schema_version());

}  // namespace balloon::store
