#pragma once
/// report.json: a job report message (balloon.v1.DesignReport, SimulateReport, FitReport) as JSON, written
/// by this one function for every path (balloon design, balloon jobs result, the HTTP files route).
#include <string>

namespace google::protobuf {
class Message;
}

namespace balloon::contract {

/// `report` in the proto3 JSON mapping with the .proto's field names (snake_case), fields in declaration
/// order and every field printed (zero, false, "" and [] too), one line and a final newline. Two rules on
/// top: an absent `optional` floating-point field (a value never computed, e.g. a design error) is `null`,
/// never 0, and other absent `optional` fields, unset oneof members and unset message fields are left out.
/// Non-finite numbers are null; map keys are sorted; int64 values are strings, as the mapping says.
/// Deterministic: the same message gives the same bytes in every process. JsonStringToMessage reads it back.
std::string report_json(const google::protobuf::Message& report);

}  // namespace balloon::contract
