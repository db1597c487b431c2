#pragma once
/// Who is calling: the tenant a token maps to. Each tenant sees only its own jobs and materials.
#include <string>

namespace balloon::service {

/// Tenant used when the server runs without a token file (a single-user, loopback-only server).
inline constexpr const char* LOCAL_TENANT = "local";

struct Caller {
  std::string tenant = LOCAL_TENANT;  ///< never the token itself
  /// May submit jobs with priority above 0: the single user of a server without a token file, or a tenant
  /// marked `raise-priority` in the token file.
  bool may_raise_priority = false;
};

}  // namespace balloon::service
