// libFuzzer target for the measurement CSV reader (parse_measurements), as a fit job's upload reaches it:
// the bytes are read as every test kind in turn, and an accepted set must pass measurement_problem.
#include <cstddef>
#include <cstdint>
#include <string>

#include "material/measurements.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (const balloon::TestKind kind : {balloon::TestKind::Uniaxial, balloon::TestKind::Equibiaxial,
                                       balloon::TestKind::PureShear, balloon::TestKind::Bulge}) {
    balloon::Result<balloon::MeasurementSet> set = balloon::parse_measurements(text, kind, "fuzz.csv");
    if (!set) {
      // One bounded line: a message that echoes a huge cell is a finding too.
      if (set.error().empty() || set.error().size() > 2000 || set.error().find_first_of("\r\n") != std::string::npos)
        __builtin_trap();
      continue;
    }
    // The parser and the checker state the same rules: what one accepts the other must accept.
    if (kind == balloon::TestKind::Bulge) {
      set->disc_radius_mm = 20.0;
      set->thickness_mm = 1.0;
    }
    if (!balloon::measurement_problem(*set).empty()) __builtin_trap();
  }
  return 0;
}
