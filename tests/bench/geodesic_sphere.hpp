#pragma once
/// Geodesic spheres: any vertex count of the form 10 n^2 + 2, not only the icosphere's powers of four.
#include "mesh/tri_mesh.hpp"

namespace balloon::bench {

/// A geodesic sphere of radius radius_mm (mm) and frequency n >= 1 (each icosahedron face cut into n^2
/// triangles, every vertex projected onto the sphere): 10 n^2 + 2 vertices, 20 n^2 faces, counter-clockwise
/// seen from outside (n = 7: 492 vertices, 10: 1,002, 64: 40,962, 100: 100,002).
balloon::TriMesh geodesic_sphere(double radius_mm, int n);

}  // namespace balloon::bench
