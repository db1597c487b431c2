#pragma once
/// Gauss-Newton directions of the reduced design problem (issue 10, "Gauss-Newton in the reduced space").
/// The objective's Gauss-Newton Hessian H in inflated coordinates (E_dist's and E_surf's, 3#V by 3#V) is
/// pulled back to rest coordinates through the equilibrium's sensitivity J = dx/drest:
///   A = P (J^T H J + R) P,   A d = -g  solved by preconditioned conjugate gradients,
/// with P the projection onto the rest changes the design allows (free coordinates, rest volume held) and
/// R the Gauss-Newton Hessian of the rest-shape terms (may be absent).
/// A product with A costs two solves with the factorization the design gradient already made (J d from
/// the linear response, J^T u from the adjoint), so a direction costs no factorization. Where L-BFGS
/// learns the curvature one step at a time and crawls along the flat valleys of a near-exact fit, this
/// model has it from the start and converges like Newton on zero-residual (matchable) targets.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <vector>

#include "design/adjoint_sensitivity.hpp"

namespace balloon {

struct GaussNewtonDirection {
  Eigen::VectorXd direction;  ///< 3#V rest change (mm); zero when none was found
  int cg_iterations = 0;
  bool descent = false;       ///< direction . gradient < 0
};

/// `sensitivity` prepared at the current equilibrium; `hessian_x` multiplies by the objective's
/// Gauss-Newton Hessian in inflated coordinates (positive semi-definite); `gradient` the projected design gradient (3#V);
/// `rest_free` the movable rest coordinates; `rest_volume_gradient` dV_rest/drest (3#V), projected out;
/// `precondition` an approximate inverse of A (applied, then projected); `hessian_rest` multiplies by R
/// (positive semi-definite; an empty function for none). CG stops at `max_iterations`, at a relative
/// residual of `tolerance`, or at a direction of non-positive curvature.
GaussNewtonDirection reduced_gauss_newton_direction(
    const AdjointSensitivity& sensitivity, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& hessian_x,
    const Eigen::VectorXd& gradient, const std::vector<bool>& rest_free, const Eigen::VectorXd& rest_volume_gradient,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& precondition, int max_iterations, double tolerance,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& hessian_rest = {});

}  // namespace balloon
