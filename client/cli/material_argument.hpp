#pragma once
/// The --material SPEC argument as the API's MaterialRef, checked locally so that a mistyped law is
/// named before anything connects.
#include <string>

#include "balloon/v1/balloon.pb.h"
#include "result.hpp"

namespace balloon::cli {

/// A preset name or an inline SPEC ("hart-smith:G=...") as given; a bare name that is no preset is sent
/// by name too (the server may have it stored). Fails for an empty or malformed SPEC, naming --material.
Result<balloon::v1::MaterialRef> material_reference(const std::string& spec);

}  // namespace balloon::cli
