#pragma once
/// What every `balloon` subcommand shares at its edges: one-line errors on stderr and output files that
/// appear whole or not at all.
#include <string>

#include <google/protobuf/message.h>

#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon::cli {

/// Prints "balloon <command>: error: <message>" as ONE line on stderr (newlines in `message` are folded)
/// and returns `exit_code`, so call sites read `return report_error(...)`.
int report_error(const std::string& command, const std::string& message, int exit_code);

/// Empty if `path` names a mesh format we can write (by extension: .obj, .stl, .ply), else the problem.
std::string mesh_output_problem(const std::string& path);

/// Writes `mesh` (mm) to `path` in the format its extension names. The file is written next to its
/// destination under a temporary name and renamed into place, so a failure leaves no partial file.
Result<bool> write_mesh_file(const TriMesh& mesh, const std::string& path);

/// Writes `bytes` to `path` through a temporary file and a rename (no partial file on failure).
Result<bool> write_file_atomically(const std::string& path, const std::string& bytes);

/// One number through a printf pattern ("%.3f"): how the summaries print measured values.
std::string format(const char* pattern, double value);

/// What an equilibrium with `unstable_modes` (> 0) unstable directions under volume control means, for a
/// summary's "stability" line: the simulate and design summaries say it alike.
std::string saddle_note(int unstable_modes);

/// A message as one line of protobuf JSON (proto field names, defaults printed): what --json prints.
std::string message_to_json(const google::protobuf::Message& message);

}  // namespace balloon::cli
