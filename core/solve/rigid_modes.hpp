#pragma once
/// Removing the six rigid-body modes of a free-floating balloon without distorting it: six coordinates
/// whose values pin translation and rotation form a statically determinate support. Under a
/// self-equilibrated load (pressure on a closed surface) their reactions vanish at equilibrium.
#include <Eigen/Core>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Six flat coordinate indices (3 * vertex + axis) on which the rigid modes of `positions` are
/// best conditioned (pivoted QR of the 6 x 3#V rigid-mode matrix).
std::vector<int> rigid_support_coordinates(const Positions& positions);

/// `step` (3#V, mm) without its infinitesimal rigid motion about the shape `x` (3#V, mm): the
/// least-squares translation and rotation subtracted.
Eigen::VectorXd without_rigid_motion(const Eigen::VectorXd& x, const Eigen::VectorXd& step);

/// Moves `x` (3#V, mm) by a rigid motion (exact rotations) so the coordinates `support` (a rigid
/// support, above) take the values they have in `held`. A rigid motion of an equilibrium is one.
/// False if `x` was already there and is unchanged.
bool restore_rigid_support(Eigen::VectorXd& x, const Eigen::VectorXd& held, const std::vector<int>& support);

}  // namespace balloon
