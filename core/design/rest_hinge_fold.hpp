#pragma once
/// A barrier that keeps the designed rest shape from folding over itself at an edge.
///
/// The sheet's bending energy (fem/hinge_bending) is k (theta - theta_rest)^2 with the difference taken
/// modulo 2 pi, so its force flips sign where an inflated hinge differs from its rest hinge by pi. On the
/// cube the design folded 22 rest hinges past 2.5 rad from the start's angle and drove the largest to
/// pi in 10 iterations; from then on every trial equilibrium started 0.28 N out of balance, whatever the
/// step's length, and the design crept at 1e-5 of its Gauss-Newton step. A mold folded flat onto
/// itself cannot be cast either.
///
/// Per interior edge, with d = |theta_rest - theta_start| (modulo 2 pi, in [0, pi]) the rest hinge's
/// turn from the start's (whose angles are the target's), the energy is
///   l0_e / L * weight * ((d - THRESHOLD) / (pi - d))^2   for d > THRESHOLD, else 0,
/// (l0_e the start's edge length, L their sum): nothing up to a right angle, unbounded at a full fold.
#include <Eigen/Core>

#include "design/distance_energy.hpp"

namespace balloon {

class RestHingeFold {
 public:
  /// Turn from the start's hinge angle below which a hinge costs nothing (rad).
  static constexpr double THRESHOLD = 0.5 * M_PI;

  /// `start` holds the start's hinges (its edges, angles and lengths); `weight` is the energy of a
  /// surface whose every hinge has r = (d - THRESHOLD) / (pi - d) = 1 (same unit as the objective).
  RestHingeFold(const DistanceEnergy& start, double weight);

  /// The energy at the flat 3#V rest positions (mm); +infinity at a full fold.
  double value(const Eigen::VectorXd& rest) const;
  /// Adds d value / d rest to `gradient` (3#V).
  void add_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// Its Gauss-Newton Hessian times `direction`: sum_e 2 w_e grad r_e (grad r_e . direction) over the
  /// hinges past the threshold. Positive semi-definite.
  Eigen::VectorXd gauss_newton_times(const Eigen::VectorXd& rest, const Eigen::VectorXd& direction) const;
  /// Hinges past the threshold at rest.
  int folded_count(const Eigen::VectorXd& rest) const;
  /// d of one hinge (rad, see above).
  double turn(const Eigen::VectorXd& rest, int hinge) const;

 private:
  /// r of `hinge` (0 below the threshold) and, when asked and r > 0, dr/d(its four corners).
  double ratio_and_gradient(const Eigen::VectorXd& rest, int hinge, Vector12d* gradient) const;
  /// theta_rest - theta_start of `hinge`, modulo 2 pi in [-pi, pi] (rad).
  double signed_turn(const Eigen::VectorXd& rest, int hinge) const;
  /// Corner k (0-3) of `hinge` at rest (mm).
  Eigen::Vector3d corner(const Eigen::VectorXd& rest, int hinge, int k) const;

  Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor> m_hinges;  ///< per hinge: v0, v1, v2, v3
  Eigen::VectorXd m_start_angles;  ///< rad
  Eigen::VectorXd m_weights;       ///< per hinge: weight * l0_e / L
};

}  // namespace balloon
