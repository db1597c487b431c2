#pragma once
/// Jobs, their progress checkpoints and their results in the store. Every method is one transaction
/// (or one statement) under the store's mutex, so each is safe to call from any thread.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "store/store.hpp"

namespace balloon::store {

/// Lifecycle of a job. Terminal: Completed, Failed, Cancelled.
enum class JobState { Queued, Running, Completed, Failed, Cancelled };

/// "queued", "running", ... as stored.
const char* to_string(JobState state);
/// Parses to_string's output; throws DatabaseError on anything else (the CHECK constraint forbids it).
JobState job_state_from_string(const std::string& text);
/// Completed, Failed or Cancelled.
inline bool is_terminal(JobState state) {
  return state == JobState::Completed || state == JobState::Failed || state == JobState::Cancelled;
}

/// One progress report as checkpointed. Distances mm, times s, residual N, pressure kPa.
struct ProgressRecord {
  std::string phase;
  int iteration = 0;
  double elapsed_s = 0.0;
  double residual_norm = 0.0;
  double pressure_kpa = 0.0;
  double avg_error_mm = -1.0;
  double max_error_mm = -1.0;
  std::int64_t recorded_ms = 0;
};

/// A job row.
struct JobRecord {
  std::int64_t row_id = 0;     ///< INTEGER PRIMARY KEY
  std::string job_id;          ///< public id
  std::string owner;           ///< tenant
  std::string kind;            ///< "simulate", "design", "fit_material"
  JobState state = JobState::Queued;
  int priority = 0;
  std::string spec;            ///< the serialized job specification (opaque here): written by insert();
                               ///< queries leave it empty (JobStore::spec reads it, when the job runs)
  std::string summary;         ///< one human line describing the spec
  std::string error;
  bool converged = false;
  std::int64_t created_ms = 0;
  std::int64_t started_ms = 0;
  std::int64_t finished_ms = 0;
  int attempts = 0;
  std::string request_id;      ///< the client's idempotency key; empty: none
  std::optional<ProgressRecord> last_progress;  ///< filled by find() and list()
};

/// A finished job's output: meshes as mesh blobs (mesh_blob.hpp) and the report.
struct ResultRecord {
  bool converged = false;
  std::string rest_mesh;
  std::string inflated_mesh;
  std::string report;       ///< the serialized report message (opaque here); empty for results stored before it
  std::string report_json;  ///< the report as JSON, kept only by results stored before `report` (else empty)
  std::string mold_mesh;    ///< design: the mold as a mesh blob; empty when there is none
  std::int64_t created_ms = 0;
};

/// A page of jobs, newest first.
struct JobPage {
  std::vector<JobRecord> jobs;
  std::int64_t next_before_row = 0;  ///< pass as before_row for the next page; 0 when this is the last
};

class JobStore {
 public:
  explicit JobStore(Store& store) : m_store(store) {}

  /// Inserts a new job (state as given, normally Queued); sets job.row_id. Durable when it returns.
  void insert(JobRecord& job);
  /// The job with this public id, whoever owns it (the caller checks the owner).
  std::optional<JobRecord> find(const std::string& job_id);
  /// The job with this row id.
  std::optional<JobRecord> find_row(std::int64_t row_id);
  /// The job's serialized spec, kept apart from its row (it holds the uploaded mesh); nullopt when the
  /// job does not exist.
  std::optional<std::string> spec(std::int64_t row_id);
  /// The owner's newest job submitted with `request_id` at or after `since_ms` (ms since the epoch).
  std::optional<JobRecord> find_request(const std::string& owner, const std::string& request_id, std::int64_t since_ms);
  /// The owner's jobs with row id < before_row (0: from the newest), optionally in one state.
  JobPage list(const std::string& owner, std::optional<JobState> state, std::int64_t before_row, int limit);

  /// Queued -> Running, attempts + 1, started_ms = now. False if the job was not queued (cancelled meanwhile).
  bool mark_running(std::int64_t row_id);
  /// Queued or Running -> Cancelled with `reason`. False if it had already finished.
  bool mark_cancelled(std::int64_t row_id, const std::string& reason);
  /// Running -> Queued: the server is shutting down or restarting and will run it again.
  void mark_requeued(std::int64_t row_id);
  /// Running -> Completed with its result, in one transaction (the result and the state appear together).
  /// False, storing nothing, if the job was no longer running (cancelled meanwhile).
  bool mark_completed(std::int64_t row_id, const ResultRecord& result);
  /// Queued or Running -> Failed with `error`.
  void mark_failed(std::int64_t row_id, const std::string& error);

  /// Appends a progress checkpoint; `shape` (float32 positions, may be empty) replaces the job's earlier
  /// stored shape, so a job keeps at most one.
  void append_progress(std::int64_t row_id, const ProgressRecord& progress, const std::string& shape);
  /// Appends several checkpoints in one transaction (not flushed to disk: a power loss may lose them);
  /// `shape` (may be empty) goes with progress[shape_index] and replaces the job's earlier stored shape.
  void append_progress_batch(std::int64_t row_id, const std::vector<ProgressRecord>& progress,
                             const std::string& shape, std::size_t shape_index);
  /// The latest checkpointed shape (float32 positions), if any.
  std::optional<std::string> latest_shape(std::int64_t row_id);
  /// Number of progress checkpoints of a job.
  int progress_count(std::int64_t row_id);

  /// Replaces the job's design checkpoint: its rest shape (an encode_mesh_blob, mm) after `iteration`.
  void save_design_checkpoint(std::int64_t row_id, int iteration, const std::string& rest_shape);
  /// The job's design checkpoint, if it has one: (iteration, rest shape blob).
  std::optional<std::pair<int, std::string>> design_checkpoint(std::int64_t row_id);

  /// Deletes a finished job with its result and progress (ON DELETE CASCADE). False, deleting nothing, if
  /// the job is queued or running (or gone).
  bool delete_finished(std::int64_t row_id);
  /// Deletes every finished job that finished before `cutoff_ms` (ms since the epoch), with its result
  /// and progress. Returns how many.
  int delete_finished_before(std::int64_t cutoff_ms);

  /// Bytes the owner's jobs take in the store: specs, results and progress checkpoints (shapes included).
  std::int64_t stored_bytes(const std::string& owner);

  /// The stored result of a completed job.
  std::optional<ResultRecord> result(std::int64_t row_id);

  /// What recover_unfinished did.
  struct Recovery {
    std::vector<JobRecord> queued;   ///< every Queued job afterwards, by priority (highest first) then age
    std::vector<JobRecord> crashed;  ///< Running jobs that had used up their attempts, now Failed
  };
  /// After a crash: a Running job (it was running when the process died) becomes Queued again, unless it
  /// has started `max_attempts` times already: then it becomes Failed with "crashed the server N times"
  /// (a job that kills the process must not crash it at every restart). max_attempts <= 0: no limit.
  Recovery recover_unfinished(int max_attempts);

 private:
  /// The one blob `sql` selects for a job row (its one parameter); nullopt when there is none.
  std::optional<std::string> blob_of_row(const char* sql, std::int64_t row_id);

  Store& m_store;
};

}  // namespace balloon::store
