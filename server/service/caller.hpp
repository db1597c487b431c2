#pragma once
/// Who is calling: the tenant a token maps to. Each tenant sees only its own jobs and materials.
#include <string>

namespace balloon::service {

/// Tenant used when the server runs without a token file (a single-user, loopback-only server).
inline constexpr const char* LOCAL_TENANT = "local";

struct Caller {
  std::string tenant = LOCAL_TENANT;  ///< never the token itself
};

}  // namespace balloon::service
