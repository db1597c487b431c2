#pragma once
/// Removing the six rigid-body modes of a free-floating balloon without distorting it: six coordinates
/// whose values pin translation and rotation form a statically determinate support. Under a
/// self-equilibrated load (pressure on a closed surface) their reactions vanish at equilibrium.
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Six flat coordinate indices (3 * vertex + axis) on which the rigid modes of `positions` are
/// best conditioned (pivoted QR of the 6 x 3#V rigid-mode matrix).
std::vector<int> rigid_support_coordinates(const Positions& positions);

}  // namespace balloon
