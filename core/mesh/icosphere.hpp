#pragma once
/// Subdivided icosahedron projected onto a sphere: the analytic test balloon.
#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Icosphere of radius radius_mm (mm) centred at the origin, faces counter-clockwise seen from outside.
/// Each subdivision splits every triangle into four: 10 * 4^k + 2 vertices and 20 * 4^k faces
/// (k = 0: 12 / 20, 2: 162 / 320, 4: 2562 / 5120, 6: 40962 / 81920). Every vertex lies on the sphere.
/// Throws std::invalid_argument unless 0 <= subdivisions <= 7 and radius_mm is finite and > 0
/// (user-facing callers validate first).
TriMesh make_icosphere(double radius_mm, int subdivisions);

}  // namespace balloon
