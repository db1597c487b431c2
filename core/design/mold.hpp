#pragma once
/// The printable dip/brush mold: the rest shape with a cylindrical inflation tube joined at the nozzle
/// (paper section 6).
#include <Eigen/Core>

#include "mesh/tri_mesh.hpp"
#include "result.hpp"

namespace balloon {

/// Builds a closed, manifold, outward-oriented solid: `rest` (closed manifold, mm) with the faces around
/// the nozzle removed and the hole's boundary loop extruded into a capped tube.
/// - The nozzle is at the vertex of `rest` closest to nozzle_center (mm); the tube axis is the
///   area-weighted outward normal of the surface within tube_radius_mm of it.
/// - Removed: the faces connected to that vertex whose centroids lie within tube_radius_mm of the axis
///   and of the nozzle (plus any small island of faces this cuts off), so the hole is one disk.
/// - Tube: rings from the hole's loop to a circle of radius tube_radius_mm over the first two rings,
///   then straight along the axis to tube_length_mm beyond the loop's outermost point, capped flat.
/// Fails with a message if the arguments are not positive and finite, the nozzle centre is far from
/// the surface, `rest` is not a valid closed mesh, or the hole is not a single simple loop (e.g. a
/// radius wider than the surface around the nozzle), or the tube would cut through a `rest` that does
/// not intersect itself. The result has the genus of `rest`.
Result<TriMesh> build_mold(const TriMesh& rest, const Eigen::Vector3d& nozzle_center, double tube_radius_mm,
                           double tube_length_mm);

}  // namespace balloon
