#pragma once
/// A barrier that keeps the designed rest triangles from collapsing into slivers.
///
/// Nothing in E_dist or E_surf looks at the rest mesh itself, and on sharp-edged targets the design
/// squeezes some rest triangles flat: the fandisk's thinnest went from 2A/l^2 = 0.31 to 0.0005 in 20
/// iterations. Such a triangle's forces answer a rest change of 1e-4 mm with a residual of 1e3 N, so
/// every trial equilibrium creeps and the design's steps shrink to 1e-5 of the Gauss-Newton step.
///
/// The term measures each rest triangle's change of shape against the same triangle of the start, not
/// of size: with C = G_start^-1 G_rest (the two triangles' metric tensors) and s1 >= s2 its singular
/// stretches, the distortion M = (s1/s2 + s2/s1)/2 - 1 = tr(C) A_start / (2 A_rest) - 1 is 0 for a scaled
/// copy and grows without bound as the triangle degenerates. Area changes, which the design needs, are
/// free. The energy is weight * sum_f (A_start,f / A_start) * max(0, M_f - THRESHOLD)^2: nothing until a
/// triangle's aspect has changed about 3.7 times, then a barrier.
#include <Eigen/Core>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

class RestTriangleQuality {
 public:
  /// Distortion below which a triangle costs nothing (M = 1: one singular stretch 3.7 times the other).
  static constexpr double THRESHOLD = 1.0;

  /// `start` is the reference shape (#V by 3, mm), `faces` its triangles; `weight` the energy of a
  /// surface whose every triangle is one unit of distortion past the threshold (same unit as the
  /// objective it joins). Degenerate start triangles are left out.
  RestTriangleQuality(const Positions& start, const Faces& faces, double weight);

  /// The energy at the flat 3#V rest positions (mm); +infinity if a distorted triangle has no area.
  double value(const Eigen::VectorXd& rest) const;
  /// Adds d value / d rest to `gradient` (3#V).
  void add_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// Its Gauss-Newton Hessian times `direction` (3#V): sum_f 2 w_f grad M_f (grad M_f . direction) over
  /// the triangles past the threshold. Positive semi-definite.
  Eigen::VectorXd gauss_newton_times(const Eigen::VectorXd& rest, const Eigen::VectorXd& direction) const;
  /// Triangles past the threshold at rest.
  int distorted_count(const Eigen::VectorXd& rest) const;
  /// M of one triangle (see above).
  double distortion(const Eigen::VectorXd& rest, int face) const;

 private:
  /// M of `face` and, when asked, its gradient with respect to the triangle's three corners (9 entries).
  double distortion_and_gradient(const Eigen::VectorXd& rest, int face, Eigen::Matrix<double, 9, 1>* gradient) const;

  Faces m_faces;
  std::vector<int> m_used_faces;           ///< faces with a non-degenerate start triangle
  Eigen::Matrix<double, Eigen::Dynamic, 3> m_inverse_metric;  ///< per face: (G^-1)_11, (G^-1)_12, (G^-1)_22
  Eigen::VectorXd m_start_area;            ///< per face (mm^2)
  Eigen::VectorXd m_face_weight;           ///< per face: weight * A_start,f / A_start
};

}  // namespace balloon
