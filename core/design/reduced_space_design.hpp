#pragma once
/// Reduced-space design (the "adjoint" method): the inflated shape is always the volume-controlled
/// equilibrium of the rest shape; L-BFGS on the rest shape with the design gradient from the adjoint
/// sensitivity, a trust region and an Armijo line search whose trials start from the linear predictor.
/// The rest volume is held at target volume / ratio. Stops as DesignStop says (matched, optimal, stalled,
/// time_limit, iteration_limit, cancelled).
#include "design/balloon_design.hpp"
#include "design/design_driver.hpp"

namespace balloon {

/// Runs the design from the driver's start (resuming from options.resume when it fits).
DesignResult run_reduced_space_design(DesignDriver& driver);

}  // namespace balloon
