#pragma once
/// The simulate flags shared by `balloon simulate` and `balloon submit`, checked locally (so errors
/// name the flag) and turned into a SubmitJob request carrying the mesh file's bytes.
#include <string>
#include <vector>

#include "arg_parser.hpp"
#include "balloon/v1/balloon.pb.h"
#include "result.hpp"

namespace balloon::cli {

/// --material, --thickness, --size, --pressure, --volume-ratio, and for a curve --volume-ratio-range or
/// --pressure-range with --points.
std::vector<OptionSpec> simulate_option_specs();

/// Checks REST_MESH (one positional) and the flags, reads the mesh file, and builds the request.
/// A bare material name that is not a preset is sent by name (the server may have it stored).
Result<balloon::v1::SubmitJobRequest> simulate_request_from_args(const ParsedArgs& args);

/// The mesh format named by a file's extension (obj, stl, ply, off, gltf, glb); UNSPECIFIED if none.
balloon::v1::MeshFormat mesh_format_from_path(const std::string& path);

}  // namespace balloon::cli
