#include "store/schema.hpp"

#include <string>
#include <vector>

#include "store/database.hpp"

namespace balloon::store {
namespace {

// Version 1: jobs, their progress checkpoints, their results, and the tenants' materials.
constexpr const char* MIGRATION_1 = R"sql(
CREATE TABLE jobs (
  id INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL UNIQUE,
  owner TEXT NOT NULL,
  kind TEXT NOT NULL,
  state TEXT NOT NULL CHECK (state IN ('queued', 'running', 'completed', 'failed', 'cancelled')),
  priority INTEGER NOT NULL DEFAULT 0,
  spec BLOB NOT NULL,
  summary TEXT NOT NULL DEFAULT '',
  error TEXT NOT NULL DEFAULT '',
  converged INTEGER NOT NULL DEFAULT 0,
  created_ms INTEGER NOT NULL,
  started_ms INTEGER NOT NULL DEFAULT 0,
  finished_ms INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX jobs_owner_id ON jobs (owner, id);
CREATE INDEX jobs_state ON jobs (state, priority, id);

CREATE TABLE progress (
  id INTEGER PRIMARY KEY,
  job_row INTEGER NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  phase TEXT NOT NULL,
  iteration INTEGER NOT NULL,
  elapsed_s REAL NOT NULL,
  residual_norm REAL NOT NULL,
  pressure_kpa REAL NOT NULL,
  avg_error_mm REAL NOT NULL,
  max_error_mm REAL NOT NULL,
  recorded_ms INTEGER NOT NULL,
  shape BLOB
);
CREATE INDEX progress_job ON progress (job_row, id);

CREATE TABLE results (
  job_row INTEGER PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
  converged INTEGER NOT NULL,
  rest_mesh BLOB NOT NULL,
  inflated_mesh BLOB NOT NULL,
  report_json TEXT NOT NULL,
  created_ms INTEGER NOT NULL
);

CREATE TABLE materials (
  id INTEGER PRIMARY KEY,
  owner TEXT NOT NULL,
  name TEXT NOT NULL,
  spec TEXT NOT NULL,
  description TEXT NOT NULL DEFAULT '',
  created_ms INTEGER NOT NULL,
  updated_ms INTEGER NOT NULL,
  UNIQUE (owner, name)
);
)sql";

// Version 2: idempotent submission (the client's request id, looked up per owner within a window).
constexpr const char* MIGRATION_2 = R"sql(
ALTER TABLE jobs ADD COLUMN request_id TEXT NOT NULL DEFAULT '';
CREATE INDEX jobs_request ON jobs (owner, request_id, created_ms) WHERE request_id <> '';
)sql";

// Version 3: the latest resumable state of a running design (its rest shape after an iteration).
constexpr const char* MIGRATION_3 = R"sql(
CREATE TABLE design_checkpoints (
  job_row INTEGER PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
  iteration INTEGER NOT NULL,
  rest_shape BLOB NOT NULL,
  recorded_ms INTEGER NOT NULL
);
)sql";

// Version 4: typed reports (a serialized balloon.v1 report message; report_json is left '' and is read only
// for results stored before) and the mold the server built with the result (a mesh blob; NULL when none).
constexpr const char* MIGRATION_4 = R"sql(
ALTER TABLE results ADD COLUMN report BLOB;
ALTER TABLE results ADD COLUMN mold_mesh BLOB;
)sql";

// Version 5: a job's spec (the whole uploaded mesh, often megabytes) in a table of its own, read only when
// the job runs. In the jobs row, every state change rewrote it (twice per job: 13 MB through the WAL for
// a 100k-vertex mesh) and every listing and lookup read it back.
constexpr const char* MIGRATION_5 = R"sql(
CREATE TABLE job_specs (
  job_row INTEGER PRIMARY KEY REFERENCES jobs (id) ON DELETE CASCADE,
  spec BLOB NOT NULL
);
INSERT INTO job_specs (job_row, spec) SELECT id, spec FROM jobs;
ALTER TABLE jobs DROP COLUMN spec;
)sql";

// Version 6: the bytes each tenant stores, kept up to date by triggers on every table that counts (specs,
// results, progress shapes plus 64 bytes a row, summaries and errors), for the quota check of every
// SubmitJob. Summed over the tenant's rows at each submit it took 13 ms under the store's lock with 1,000
// finished jobs stored, and grew with the history. A job's rows go in its own BEFORE DELETE trigger, while
// the job still names their owner (a cascade would delete them after it). REPLACE deletes fire triggers
// because the connection turns recursive_triggers on (Database). length() of a BLOB reads its size, not
// its bytes.
constexpr const char* MIGRATION_6 = R"sql(
CREATE TABLE tenant_usage (
  owner TEXT PRIMARY KEY,
  bytes INTEGER NOT NULL DEFAULT 0
) WITHOUT ROWID;
INSERT INTO tenant_usage (owner, bytes)
  SELECT owner, SUM(LENGTH(summary) + LENGTH(error)) FROM jobs GROUP BY owner;
UPDATE tenant_usage SET bytes = bytes
  + (SELECT COALESCE(SUM(LENGTH(s.spec)), 0) FROM job_specs AS s JOIN jobs AS j ON j.id = s.job_row
     WHERE j.owner = tenant_usage.owner)
  + (SELECT COALESCE(SUM(LENGTH(r.rest_mesh) + LENGTH(r.inflated_mesh) + LENGTH(CAST(r.report_json AS BLOB)) +
                         COALESCE(LENGTH(r.report), 0) + COALESCE(LENGTH(r.mold_mesh), 0)), 0)
     FROM results AS r JOIN jobs AS j ON j.id = r.job_row WHERE j.owner = tenant_usage.owner)
  + (SELECT COALESCE(SUM(COALESCE(LENGTH(p.shape), 0) + 64), 0)
     FROM progress AS p JOIN jobs AS j ON j.id = p.job_row WHERE j.owner = tenant_usage.owner);

CREATE TRIGGER usage_job_insert AFTER INSERT ON jobs BEGIN
  INSERT INTO tenant_usage (owner, bytes) VALUES (NEW.owner, 0) ON CONFLICT (owner) DO NOTHING;
  UPDATE tenant_usage SET bytes = bytes + LENGTH(NEW.summary) + LENGTH(NEW.error) WHERE owner = NEW.owner;
END;
CREATE TRIGGER usage_job_update AFTER UPDATE OF summary, error ON jobs BEGIN
  UPDATE tenant_usage SET bytes = bytes + LENGTH(NEW.summary) + LENGTH(NEW.error) - LENGTH(OLD.summary) - LENGTH(OLD.error)
    WHERE owner = NEW.owner;
END;
CREATE TRIGGER usage_job_delete BEFORE DELETE ON jobs BEGIN
  DELETE FROM job_specs WHERE job_row = OLD.id;
  DELETE FROM results WHERE job_row = OLD.id;
  DELETE FROM progress WHERE job_row = OLD.id;
  UPDATE tenant_usage SET bytes = bytes - LENGTH(OLD.summary) - LENGTH(OLD.error) WHERE owner = OLD.owner;
END;
CREATE TRIGGER usage_spec_insert AFTER INSERT ON job_specs BEGIN
  UPDATE tenant_usage SET bytes = bytes + LENGTH(NEW.spec) WHERE owner = (SELECT owner FROM jobs WHERE id = NEW.job_row);
END;
CREATE TRIGGER usage_spec_delete AFTER DELETE ON job_specs BEGIN
  UPDATE tenant_usage SET bytes = bytes - LENGTH(OLD.spec) WHERE owner = (SELECT owner FROM jobs WHERE id = OLD.job_row);
END;
CREATE TRIGGER usage_result_insert AFTER INSERT ON results BEGIN
  UPDATE tenant_usage SET bytes = bytes + LENGTH(NEW.rest_mesh) + LENGTH(NEW.inflated_mesh) +
    LENGTH(CAST(NEW.report_json AS BLOB)) + COALESCE(LENGTH(NEW.report), 0) + COALESCE(LENGTH(NEW.mold_mesh), 0)
    WHERE owner = (SELECT owner FROM jobs WHERE id = NEW.job_row);
END;
CREATE TRIGGER usage_result_delete AFTER DELETE ON results BEGIN
  UPDATE tenant_usage SET bytes = bytes - LENGTH(OLD.rest_mesh) - LENGTH(OLD.inflated_mesh) -
    LENGTH(CAST(OLD.report_json AS BLOB)) - COALESCE(LENGTH(OLD.report), 0) - COALESCE(LENGTH(OLD.mold_mesh), 0)
    WHERE owner = (SELECT owner FROM jobs WHERE id = OLD.job_row);
END;
CREATE TRIGGER usage_progress_insert AFTER INSERT ON progress BEGIN
  UPDATE tenant_usage SET bytes = bytes + COALESCE(LENGTH(NEW.shape), 0) + 64
    WHERE owner = (SELECT owner FROM jobs WHERE id = NEW.job_row);
END;
CREATE TRIGGER usage_progress_shape AFTER UPDATE OF shape ON progress BEGIN
  UPDATE tenant_usage SET bytes = bytes + COALESCE(LENGTH(NEW.shape), 0) - COALESCE(LENGTH(OLD.shape), 0)
    WHERE owner = (SELECT owner FROM jobs WHERE id = NEW.job_row);
END;
CREATE TRIGGER usage_progress_delete AFTER DELETE ON progress BEGIN
  UPDATE tenant_usage SET bytes = bytes - COALESCE(LENGTH(OLD.shape), 0) - 64
    WHERE owner = (SELECT owner FROM jobs WHERE id = OLD.job_row);
END;
)sql";

// Version 7: a listing of one state (`balloon jobs list --state running`) reads that state's rows only;
// through jobs_owner_id it walked every job the owner has.
constexpr const char* MIGRATION_7 = R"sql(
CREATE INDEX jobs_owner_state ON jobs (owner, state, id);
)sql";

const std::vector<const char*>& migrations() {
  static const std::vector<const char*> list = {MIGRATION_1, MIGRATION_2, MIGRATION_3, MIGRATION_4,
                                                MIGRATION_5, MIGRATION_6, MIGRATION_7};
  return list;
}

int user_version(Database& database) {
  Statement statement = database.prepare("PRAGMA user_version");
  return statement.step() ? statement.column_int(0) : 0;
}

}  // namespace

int current_schema_version() { return static_cast<int>(migrations().size()); }

void migrate(Database& database, int target) {
  if (target < 0 || target > current_schema_version())
    throw DatabaseError("no schema version " + std::to_string(target) + " to migrate to");
  int version = user_version(database);
  if (version > current_schema_version())
    throw DatabaseError("database '" + database.path() + "' has schema version " + std::to_string(version) +
                        ", newer than this build's " + std::to_string(current_schema_version()));
  while (version < target) {
    Transaction transaction(database);
    // Re-read inside the write lock: another process may have migrated meanwhile.
    version = user_version(database);
    if (version >= target) break;
    database.execute(migrations()[static_cast<std::size_t>(version)]);
    database.execute("PRAGMA user_version = " + std::to_string(version + 1));
    transaction.commit();
    ++version;
  }
}

}  // namespace balloon::store
