#pragma once
/// Coarse-to-fine design (issue 10, "Multiresolution"). The adjoint design first runs on the target
/// remeshed to about DesignOptions::coarse_vertices: there an iteration costs a sixth of one at 4,000
/// vertices, and the large-scale shape of the rest balloon is what most of the iterations fix. The
/// coarse rest shape's change from its start is then carried to the full-resolution start (barycentric
/// interpolation on the coarse target, surface_transfer.hpp), and the design continues from that rest
/// shape at full resolution as from a checkpoint: the full-resolution start is still inflated for the
/// baseline, and a carried shape that cannot be inflated is dropped (the design starts over there).
#include "design/balloon_design.hpp"

namespace balloon {

/// True when `options` ask for a coarse stage and `target` is large enough to gain from one.
bool runs_coarse_to_fine(const TriMesh& target, const DesignOptions& options);

/// The design of `target` with a coarse stage first (see above); `target` and `options` as for
/// design_balloon, which calls this when runs_coarse_to_fine() holds.
DesignResult design_coarse_to_fine(const TriMesh& target, const DesignOptions& options);

/// The coarse rest shape's change from the coarse start, carried to the full-resolution start:
/// start_fine + change interpolated at the full-resolution target's vertices (both starts are their
/// target scaled about its centroid, so this keeps the full-resolution target's detail).
Positions carry_rest_shape(const TriMesh& coarse_target, const Positions& coarse_start, const Positions& coarse_rest,
                           const TriMesh& fine_target, const Positions& fine_start);

}  // namespace balloon
