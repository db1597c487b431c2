#pragma once
/// An inflation from rest run on a thread of its own while the design goes on. The design checks every few
/// iterations that its rest shape, inflated from rest, reaches its own shape (reduced_space_design.cpp): one
/// forward inflation (1-6 s with latex at 4,000 vertices, about 40% of a latex design's budget while it held
/// the design up). The design itself runs on one core; the check takes the machine's second.
#include <future>
#include <memory>

#include "progress.hpp"
#include "solve/inflation.hpp"

namespace balloon {

class BackgroundInflation {
 public:
  BackgroundInflation() = default;
  BackgroundInflation(const BackgroundInflation&) = delete;
  BackgroundInflation& operator=(const BackgroundInflation&) = delete;
  ~BackgroundInflation() { abandon(); }

  /// Starts inflate(rest, options) on a thread of its own (one at a time: a running one is abandoned
  /// first). The thread has the caller's niceness. `options.cancel`, the caller's token, still cancels it
  /// (as it starts, and within 50 ms while wait() waits) and must outlive it.
  void start(TriMesh rest, InflationOptions options);
  /// Whether an inflation was started and not yet waited for or abandoned.
  bool running() const { return m_result.valid(); }
  /// Waits for the inflation started last and hands back its result. Requires running().
  InflationResult wait();
  /// Cancels a running inflation and waits for its thread to end; does nothing when none runs.
  void abandon();

 private:
  const CancelToken* m_caller_cancel = nullptr;
  std::unique_ptr<CancelToken> m_cancel;  ///< this inflation's own token (a token cannot be reset)
  std::future<InflationResult> m_result;
};

}  // namespace balloon
