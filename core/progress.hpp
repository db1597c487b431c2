#pragma once
/// What a long run tells the outside world, and how the outside world stops it.
/// This is the only thing the service sees of a run.
#include <atomic>
#include <functional>
#include <string>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Set from any thread; long runs check it between iterations and stop cleanly.
class CancelToken {
 public:
  void cancel() { m_cancelled.store(true, std::memory_order_relaxed); }
  bool cancelled() const { return m_cancelled.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> m_cancelled{false};
};

/// One progress report. Distances in mm, times in s.
struct ProgressEvent {
  std::string phase;              ///< e.g. "inflate", "design", "fit"
  int iteration = 0;              ///< iteration within the phase
  double elapsed_s = 0.0;         ///< wall time since the run started
  double avg_error_mm = -1.0;     ///< design only; -1 when not applicable
  double max_error_mm = -1.0;     ///< design only; -1 when not applicable
  double residual_norm = 0.0;     ///< force residual norm (N)
  double pressure_kpa = 0.0;      ///< current pressure (kPa)
  const Positions* shape = nullptr;  ///< current inflated positions (mm), set every K iterations, else null
  /// Design only: the rest shape (mm) the event's iteration reached, for a checkpoint to resume from.
  const Positions* rest_shape = nullptr;
};

/// Receives progress events; may be empty.
using ProgressCallback = std::function<void(const ProgressEvent&)>;

}  // namespace balloon
