#pragma once
/// The design's progress bar on stderr, shared by `balloon design` and `balloon jobs watch`.
#include "balloon/v1/balloon.pb.h"
#include "job_watch.hpp"

namespace balloon::cli {

/// On a terminal: a bar with iteration, average error and ETA; otherwise plain lines (ProgressPrinter).
class DesignProgress {
 public:
  /// `max_time_s` > 0 bounds the ETA (the design's --max-time); 0 when unknown.
  DesignProgress(bool terminal, double max_time_s);
  ~DesignProgress();
  void operator()(const balloon::v1::JobEvent& event);

 private:
  bool m_terminal;
  double m_max_time_s;
  ProgressPrinter m_lines;
  bool m_open = false;
};

}  // namespace balloon::cli
