#pragma once
/// A problem with one parameter of a job, named by the field's path in the job's proto message, so the
/// service (as a google.rpc.BadRequest field violation) and the CLI (as its flag) point at the input that
/// caused it without reading the wording.
#include <string>
#include <vector>

namespace balloon::jobs {

struct FieldProblem {
  std::string field;    ///< the field in the job message (DesignJob, SimulateJob), e.g. "thickness_mm"
  std::string message;  ///< one line naming the problem, e.g. "thickness must be a positive number of mm, got -1"
};

/// Every problem's message joined by "; " (one line); empty when there is none.
inline std::string joined_messages(const std::vector<FieldProblem>& problems) {
  std::string text;
  for (const FieldProblem& problem : problems) text += (text.empty() ? "" : "; ") + problem.message;
  return text;
}

}  // namespace balloon::jobs
