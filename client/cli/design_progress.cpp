#include "design_progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "design/balloon_design.hpp"

namespace balloon::cli {

DesignProgress::DesignProgress(bool terminal, double max_time_s)
    : m_terminal(terminal), m_max_time_s(max_time_s), m_lines(true) {}

DesignProgress::~DesignProgress() {
  if (m_open) std::fputc('\n', stderr);
}

void DesignProgress::operator()(const balloon::v1::JobEvent& event) {
  if (!m_terminal || !event.has_progress() || event.progress().phase() != "design") {
    if (m_open) std::fputc('\n', stderr);
    m_open = false;
    m_lines(event);
    return;
  }
  const balloon::v1::Progress& p = event.progress();
  const int budget = DesignOptions{}.max_iterations;
  double fraction = std::min(1.0, static_cast<double>(p.iteration()) / budget);
  double eta = p.iteration() > 0 ? p.elapsed_s() / p.iteration() * std::max(0, budget - p.iteration()) : -1.0;
  if (m_max_time_s > 0.0) {
    fraction = std::max(fraction, std::min(1.0, p.elapsed_s() / m_max_time_s));
    const double left = std::max(0.0, m_max_time_s - p.elapsed_s());
    eta = eta < 0.0 ? left : std::min(eta, left);
  }
  constexpr int WIDTH = 30;
  const int filled = static_cast<int>(std::lround(fraction * WIDTH));
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.append(static_cast<std::size_t>(WIDTH - filled), '-');
  char eta_text[32] = "?";
  if (eta >= 0.0) std::snprintf(eta_text, sizeof(eta_text), "%.0f s", eta);
  std::fprintf(stderr, "\r\033[K[%s] it %d  avg error %.3g mm  max %.3g mm  %.1f s  ETA %s", bar.c_str(), p.iteration(),
               p.avg_error_mm(), p.max_error_mm(), p.elapsed_s(), eta_text);
  std::fflush(stderr);
  m_open = true;
}

}  // namespace balloon::cli
