#pragma once
/// The design objective and its terms (paper sec. 5): E_dist(x) (eq. 18) against the target, the surface
/// term E_surf(x) (the error the result reports), and the rest-shape regularizers R(rest) that join only
/// when the scene needs them: rest collisions (eq. 24), rest bending against the start (flat starts), the
/// maximum-volume term (alm, once a rest region has turned inside out), and two barriers on the rest mesh
/// (once a triangle's shape or a hinge's angle has changed past its threshold). Both optimizers minimise
/// value(rest, x) with x the inflated shape of rest; they differ in how they keep x an equilibrium.
/// Positions are flat 3#V vectors (mm).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "design/balloon_design.hpp"
#include "design/distance_energy.hpp"
#include "design/objective_gauss_newton.hpp"
#include "design/procrustes_placement.hpp"
#include "design/rest_hinge_fold.hpp"
#include "design/rest_triangle_quality.hpp"
#include "design/self_collision.hpp"
#include "design/surface_distance.hpp"
#include "fem/balloon_model.hpp"

namespace balloon {

class DesignObjective {
 public:
  /// `target` is the shape to reach, `start` the start rest shape (its hinges are the rest-bending
  /// reference, its edges the collision scale); `model` gives the rest volume's gradient. `target` and
  /// `model` must outlive this object.
  DesignObjective(const TriMesh& target, const TriMesh& start, const DesignOptions& options,
                  const fem::BalloonModel& model);

  /// E_dist + E_surf at x plus the active regularizers at rest.
  double value(const Eigen::VectorXd& rest, const Eigen::VectorXd& x) const;
  /// d(E_dist + E_surf)/dx (3#V).
  Eigen::VectorXd shape_gradient(const Eigen::VectorXd& x) const;
  /// E_surf at x; its gradient into `gradient` when given.
  double surface_term(const Eigen::VectorXd& x, Eigen::VectorXd* gradient) const;

  /// The rest-shape terms that are active: collisions, rest bending, maximum volume.
  double regularizer_value(const Eigen::VectorXd& rest) const;
  /// Adds the gradient of regularizer_value to `gradient`.
  void add_regularizer_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// The Gauss-Newton Hessian of the rest mesh's barriers times `direction` (3#V; zero while no triangle
  /// or hinge is past its threshold). The other regularizers are left out of the Gauss-Newton model.
  Eigen::VectorXd regularizer_gauss_newton_times(const Eigen::VectorXd& rest, const Eigen::VectorXd& direction) const;

  /// Sets E_surf's weight to k_surface times its growth after `iterations` iterations (see
  /// DesignOptions::surface_growth); true when that changed it, i.e. value() and its gradient changed.
  bool grow_surface_weight(int iterations);
  /// k_surface times the growth set last (dimensionless).
  double surface_weight() const { return m_k_surface * m_surface_growth_now; }

  /// Gauss-Newton Hessian of E_dist + E_surf at x, as an operator (the regularizers are left out).
  ObjectiveGaussNewton gauss_newton(const Eigen::VectorXd& x) const;

  /// Gauss-Newton Hessian of E_surf, point-to-plane, as triplets shifted by dof_offset.
  void add_surface_hessian(const Eigen::VectorXd& x, std::vector<Eigen::Triplet<double>>& triplets,
                           int dof_offset) const;

  /// Updates the colliding rest pairs at `rest` (once per accepted step) and lists "collision" in
  /// `result` the first time any is near. True when the collision term was or is on, i.e. value() at
  /// rest may differ from before the update.
  bool update_collisions(const Eigen::VectorXd& rest, DesignResult& result);

  /// Lists "rest_quality" in `result` the first time a rest triangle is past its barrier's threshold, and
  /// "rest_fold" the first time a rest hinge is.
  void note_rest_barriers(const Eigen::VectorXd& rest, DesignResult& result);

  /// Once a rest region has turned inside out, the maximum-volume term (paper sec. 5.2) joins the
  /// objective, weighted so that a 1% volume change is worth 1% of the start's E_dist.
  void update_max_volume_term(const Eigen::VectorXd& rest, double start_distance, DesignResult& result);

  /// Moves the inflated shape x rigidly onto the target (vertex correspondence) when that moves it by
  /// more than a 1e-4 of the diagonal on average, and says whether it did. No term's value changes (E_surf
  /// is taken at that placement anyway); it keeps the pinned coordinates near the target.
  bool realign(Eigen::VectorXd& x) const;

  /// Active terms every method shares (the method adds its own).
  void list_common_terms(DesignResult& result, bool nozzle) const;

  const DistanceEnergy& distance() const { return m_distance; }
  const DistanceEnergy& start_hinges() const { return m_start_hinges; }
  const SurfaceDistance& surface() const { return m_surface; }
  bool rest_bending_active() const { return m_rest_bending_active; }

 private:
  /// Per point, the unit normal of the target triangle closest to it (a zero row where that triangle is
  /// degenerate).
  Positions closest_target_normals(const Positions& points) const;
  /// w of E_surf = w sum_i d_i^2 now (mm^-1); 0 when k_surface is 0.
  double surface_weight_mm() const { return m_k_surface * m_surface_growth_now * m_unit_surface_weight; }
  /// Hinges of `rest` whose dihedral angle moved more than a right angle from the start's.
  int inverted_hinges(const Eigen::VectorXd& rest) const;

  const TriMesh& m_target;
  const fem::BalloonModel& m_model;
  DistanceEnergy m_distance;
  SurfaceDistance m_surface;
  DistanceEnergy m_start_hinges;  ///< the start's hinge angles; with k_length 0 it is the rest-bending term
  std::unique_ptr<SelfCollision> m_collision;
  RestTriangleQuality m_rest_quality;
  RestHingeFold m_rest_fold;
  bool m_rest_quality_seen = false, m_rest_fold_seen = false;
  bool m_collision_seen = false;
  bool m_rest_bending_active = false;
  double m_unit_surface_weight = 0.0;  ///< w of E_surf = w sum_i d_i^2 for k_surface = 1 (mm^-1)
  double m_k_surface = 0.0;
  double m_surface_growth = 1.0, m_max_surface_growth = 1.0, m_surface_growth_now = 1.0;
  int m_surface_growth_iterations = 1;
  double m_max_volume_weight = 0.0;  ///< alm: weight of -V(rest) once a region turned inside out (mm^-2)
  double m_start_volume = 0.0;       ///< the start's rest volume (mm^3)
};

}  // namespace balloon
