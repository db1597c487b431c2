#pragma once
/// Sensitivities of the volume-controlled equilibrium x(rest) (paper sec. 5.1): at an equilibrium,
///   [K  -v] [dx]   [-M d_rest]
///   [-v^T 0] [dp] = [    0    ]
/// with K the stiffness (N/mm), v = dV/dx (mm^2), M = d grad_x W / d rest (N/mm, the membrane's mixed
/// derivative) and p the pressure (MPa), which is the volume constraint's multiplier. The design's reduced
/// gradient (adjoint) and its linear predictor (the first-order response to a rest step) both solve with
/// the one factorization of K made in `prepare`. Positions are flat 3#V vectors (mm).
#include <Eigen/Core>
#include <vector>

#include "fem/hinge_bending.hpp"
#include "fem/membrane_element.hpp"

#include "fem/balloon_model.hpp"
#include "solve/equilibrium_solver.hpp"

namespace balloon {

class AdjointSensitivity {
 public:
  /// `model` and `solver` are the design's: the model's rest positions, material and per-element
  /// thickness are the ones differentiated. Both must outlive this object.
  AdjointSensitivity(const fem::BalloonModel& model, EquilibriumSolver& solver);

  /// Factorizes K at the equilibrium (x, pressure_mpa) of the model's current rest shape `rest`, solves
  /// K b = v once, and evaluates M's element blocks once (the Gauss-Newton directions apply M and M^T
  /// about forty times per iteration). False when K is singular or v^T K^-1 v vanishes (no sensitivity
  /// is defined).
  bool prepare(const Eigen::VectorXd& rest, const Eigen::VectorXd& x, double pressure_mpa);

  /// dJ/d rest (3#V) of J(x(rest)) at the prepared equilibrium, from `objective_gradient_x` = dJ/dx
  /// (3#V): one adjoint solve K lambda = dJ/dx, projected so that the volume stays fixed, then -M^T lambda.
  Eigen::VectorXd gradient(const Eigen::VectorXd& objective_gradient_x) const;

  /// First-order change (dx, dp) of the equilibrium for a rest change `direction` (3#V, mm); zero when
  /// the solve is not finite.
  void linear_response(const Eigen::VectorXd& direction, Eigen::VectorXd& dx, double& dp) const;

  /// M s (transpose false) or M^T s (transpose true) at (rest, x): how the forces change with the rest
  /// shape, or how forces weighted by s change with it. Summed over triangles (and the sheet's bending
  /// hinges when on); 3#V in and out. Evaluates the element blocks at (rest, x) anew.
  Eigen::VectorXd mixed_product(const Eigen::VectorXd& rest, const Eigen::VectorXd& x, const Eigen::VectorXd& s,
                                bool transpose) const;

  /// dV/dp (mm^3/MPa) along the pressure-volume curve of the prepared rest shape at its equilibrium:
  /// v^T K^-1 v. Positive on the rising branch, negative past a pressure maximum (where the balloon would
  /// snap under pressure control and only the volume holds it).
  double volume_per_pressure() const { return m_volume_gradient.dot(m_volume_response); }

  /// v = dV/dx and K^-1 v at the prepared equilibrium.
  const Eigen::VectorXd& volume_gradient() const { return m_volume_gradient; }
  const Eigen::VectorXd& volume_response() const { return m_volume_response; }

 private:
  /// M's element blocks: one 9x9 per triangle, one 12x12 per bending hinge (none when bending is off).
  struct MixedBlocks {
    std::vector<fem::Matrix9d> triangles;
    std::vector<fem::Matrix12d> hinges;
  };
  MixedBlocks mixed_blocks(const Eigen::VectorXd& rest, const Eigen::VectorXd& x) const;
  Eigen::VectorXd apply_mixed(const MixedBlocks& blocks, const Eigen::VectorXd& s, bool transpose) const;

  const fem::BalloonModel& m_model;
  EquilibriumSolver& m_solver;
  MixedBlocks m_mixed;  ///< at the prepared (rest, x)
  Eigen::VectorXd m_volume_gradient, m_volume_response;
};

}  // namespace balloon
