#include "design/background_inflation.hpp"

#include <chrono>
#include <utility>

namespace balloon {

namespace {

/// How often wait() looks at the caller's cancel token: a cancelled design stops within this.
constexpr std::chrono::milliseconds CANCEL_POLL{50};

}  // namespace

void BackgroundInflation::start(TriMesh rest, InflationOptions options) {
  abandon();
  m_caller_cancel = options.cancel;
  m_cancel = std::make_unique<CancelToken>();
  if (m_caller_cancel && m_caller_cancel->cancelled()) m_cancel->cancel();
  options.cancel = m_cancel.get();
  m_result = std::async(std::launch::async, [rest = std::move(rest), options = std::move(options)] {
    return inflate(rest, options);
  });
}

InflationResult BackgroundInflation::wait() {
  while (m_result.wait_for(CANCEL_POLL) != std::future_status::ready)
    if (m_caller_cancel && m_caller_cancel->cancelled()) m_cancel->cancel();
  return m_result.get();
}

void BackgroundInflation::abandon() {
  if (!running()) return;
  m_cancel->cancel();
  m_result.wait();
  m_result = {};
}

}  // namespace balloon
