#pragma once
/// Reading and writing triangle meshes. The only place that knows about file formats (and assimp).
#include <string>

#include "mesh/mesh_read_limits.hpp"
#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// Reads a triangle mesh; the format comes from the extension, case-insensitive: obj, stl (ASCII or
/// binary), ply, off, gltf, glb. Coordinates are taken as mm whatever the format (glTF's metres
/// included). OBJ and OFF keep the file's vertex order and double precision; STL, PLY and glTF go
/// through assimp (single precision), their vertices welded by exact position (an STL is a triangle
/// soup) and glTF node transforms applied. All meshes and nodes of a file are merged into one mesh.
/// Fails with a one-line message naming the file and the problem: unreadable file, unknown extension,
/// parse error (with line), a face that is not a triangle (with its face index), no triangles.
/// The mesh is not validated: see validate_balloon_mesh.
Result<TriMesh> read_mesh(const std::string& path);

/// As read_mesh, from the bytes of a file (an upload); format is the extension without the dot ("obj",
/// "stl", ..., case-insensitive). Reads these bytes and nothing else: a glTF must embed its buffers (data:
/// URIs) and one naming another file is refused with that name. Non-finite coordinates are refused, and
/// the counts are checked against `limits` before allocation where the format declares them (OFF, PLY,
/// binary STL), while parsing otherwise; the message names the count and the limit.
Result<TriMesh> read_mesh_from_memory(const std::string& bytes, const std::string& format,
                                      const MeshReadLimits& limits = {});

/// Writes `mesh` (positions in mm) as OBJ (%.9g), binary STL or binary little-endian PLY (double
/// coordinates), chosen by the extension (case-insensitive). Writes a temporary file in the same
/// directory and renames it, so a failure leaves no partial file; returns true or a message naming
/// the file and the problem. Throws std::invalid_argument if a face index is out of range.
Result<bool> write_mesh(const TriMesh& mesh, const std::string& path);

/// The bytes write_mesh would write for format "obj", "stl" or "ply" (case-insensitive, deterministic).
/// Throws std::invalid_argument for another format (check with is_writable_mesh_format) or a face
/// index out of range.
std::string write_mesh_to_memory(const TriMesh& mesh, const std::string& format);

/// True if read_mesh accepts this format (extension with or without the dot, any case).
bool is_readable_mesh_format(const std::string& format);
/// True if write_mesh accepts this format (obj, stl, ply; with or without the dot, any case).
bool is_writable_mesh_format(const std::string& format);

}  // namespace balloon
