#pragma once
/// Everything the service layer is configured with; balloon-server's flags fill it. Defaults are the
/// documented flag defaults.
#include <functional>
#include <string>

namespace balloon::service {

struct ServiceOptions {
  std::string db_path = "balloon.db";   ///< SQLite file; ":memory:" for a throw-away store
  int workers = 0;                      ///< worker threads; 0 means the number of cores
  int max_queue = 1000;                 ///< queued jobs at most (running ones not counted)
  int max_mesh_vertices = 200000;       ///< larger meshes are refused (RESOURCE_EXHAUSTED)
  double job_time_limit_s = 3600.0;     ///< per-job wall-time limit (s); a job may ask for less
  int progress_mesh_every = 1;          ///< default K: every K-th shape-carrying progress event streams the mesh
  double checkpoint_interval_s = 0.25;  ///< at most one stored progress checkpoint per job per interval (s)
  bool recover = true;                  ///< re-queue unfinished jobs at start (only if no other process uses the store)
  /// false: the jobs recover re-queues stay queued in the store and this process does not run them (an
  /// embedded CLI command runs its own job only; `jobs watch` runs the rest)
  bool run_recovered = true;
  int max_attempts = 3;                 ///< a job found running at start after this many starts FAILS; 0 no limit
  int max_queued_per_tenant = 100;      ///< queued jobs per tenant; more get RESOURCE_EXHAUSTED; 0 no limit
  int max_running_per_tenant = 4;       ///< jobs of one tenant running at once (others wait their turn); 0 no limit
  int max_watches_per_tenant = 64;      ///< open watch streams per tenant; more get RESOURCE_EXHAUSTED; 0 no limit
  int max_stored_mb_per_tenant = 2048;  ///< MiB of specs and results a tenant may store; 0 no limit
  double retention_days = 90.0;         ///< finished jobs older than this are deleted (days); 0 keeps them forever
  /// true: a submitted job, a result or a state change is on disk (fdatasync) before the call returns.
  /// false (the CLI's embedded store): commits survive a crash of the process, not of the machine.
  bool durable_store = true;
  bool run_jobs = true;                 ///< false: accept and store jobs but start no workers (a short-lived CLI)
  std::string shard_name;               ///< --shard-name: prefixes every new job id ("s2-j-..."); empty: none
  /// Receives one log line per job event; empty for silence (the embedded CLI server).
  std::function<void(const std::string&)> log;
};

}  // namespace balloon::service
