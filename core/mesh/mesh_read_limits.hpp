#pragma once
/// Bounds on a mesh file, checked while reading (before allocation where the format declares its counts).
#include <cstdint>
#include <string>

namespace balloon {

/// Largest mesh a reader accepts; 0 means no limit. The server sets both from its flags.
struct MeshReadLimits {
  std::int64_t max_vertices = 0;  ///< vertices of the mesh read (after welding, for the formats that weld)
  std::int64_t max_faces = 0;     ///< triangles (and other polygons) of the mesh read
};

/// Every message of a reader that refused a mesh for its size starts with this (callers map it to
/// "resource exhausted" rather than "bad input").
inline constexpr const char* OVER_LIMIT_PREFIX = "too many ";

/// True if a reader's error message (with any context before it) is a size-limit refusal.
inline bool is_over_limit_error(const std::string& message) {
  return message.find(std::string(": ") + OVER_LIMIT_PREFIX) != std::string::npos || message.rfind(OVER_LIMIT_PREFIX, 0) == 0;
}

/// The limits a server with a vertex limit applies to an upload (0: none). A closed mesh of genus g has
/// F = 2V - 4 + 4g faces, so 4 faces per vertex leaves room for any genus a balloon can have.
inline MeshReadLimits upload_limits(std::int64_t max_vertices) {
  return MeshReadLimits{max_vertices, 4 * max_vertices};
}

/// "", or the message for `count` items of `what` ("vertices", "faces") over `limit` (0: no limit).
inline std::string over_limit_message(std::int64_t count, std::int64_t limit, const char* what) {
  if (limit <= 0 || count <= limit) return {};
  return OVER_LIMIT_PREFIX + std::string(what) + ": " + std::to_string(count) + " (the limit is " + std::to_string(limit) + ")";
}

}  // namespace balloon
