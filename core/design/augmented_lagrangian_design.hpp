#pragma once
/// The paper's method (sec. 5.2, "alm"): an augmented Lagrangian over rest and inflated positions
/// together, with the nodal force balance as the constraint, solved by damped Gauss-Newton; at the end
/// the rest shape is inflated properly, so the reported errors are a true equilibrium's.
#include "design/balloon_design.hpp"
#include "design/design_driver.hpp"

namespace balloon {

/// Runs the design from the driver's start.
DesignResult run_augmented_lagrangian_design(DesignDriver& driver);

}  // namespace balloon
