#pragma once
/// Pressure as the conservative load -p V(x) of a closed surface (paper eq. 13): the gradient of the
/// enclosed volume at a vertex is a third of the area-weighted normals of its triangles, so p * grad V
/// are the paper's nodal pressure forces. Per-triangle terms of the signed volume V = sum x1.(x2 x x3)/6;
/// for an open surface (a clamped disc) V is the volume of the cone to the origin, which is the volume
/// under the membrane when the fixed rim lies in a plane through the origin.
#include "fem/membrane_element.hpp"

namespace balloon::fem {

/// Signed volume x1.(x2 x x3)/6 of the tetrahedron (origin, x1, x2, x3) (mm^3).
double triangle_signed_volume(const Vector9d& x);
/// Its gradient (9, mm^2).
Vector9d triangle_volume_gradient(const Vector9d& x);
/// Its Hessian (9x9, mm): constant-free, linear in x.
Matrix9d triangle_volume_hessian(const Vector9d& x);

}  // namespace balloon::fem
