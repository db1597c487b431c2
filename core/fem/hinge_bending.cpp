#include "fem/hinge_bending.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <utility>

#include <unsupported/Eigen/AutoDiff>

namespace balloon::fem {
namespace {

/// Gradient of the dihedral angle in closed form (Bridson, Marino and Fedkiw, "Simulation of clothing with
/// folds and wrinkles", SCA 2003): each triangle's normal direction, weighted by the lever arms of its
/// vertices about the hinge. A template so that forward-mode automatic differentiation of it gives the
/// Hessian.
template <typename T>
Eigen::Matrix<T, 12, 1> dihedral_angle_gradient(const Eigen::Matrix<T, 12, 1>& x) {
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  using std::sqrt;
  const Vector3 x0 = x.template segment<3>(0), x1 = x.template segment<3>(3), x2 = x.template segment<3>(6),
                x3 = x.template segment<3>(9);
  const Vector3 edge = x1 - x0;
  const Vector3 normal_a = edge.cross(x2 - x0);
  const Vector3 normal_b = (x0 - x1).cross(x3 - x1);
  const T length = sqrt(edge.squaredNorm());
  const Vector3 a = normal_a / normal_a.squaredNorm();
  const Vector3 b = normal_b / normal_b.squaredNorm();
  const Vector3 unit_edge = edge / length;
  Eigen::Matrix<T, 12, 1> g;
  g.template segment<3>(0) = -((x2 - x1).dot(unit_edge) * a + (x3 - x1).dot(unit_edge) * b);
  g.template segment<3>(3) = (x2 - x0).dot(unit_edge) * a + (x3 - x0).dot(unit_edge) * b;
  g.template segment<3>(6) = -length * a;
  g.template segment<3>(9) = -length * b;
  return g;
}

/// |e|^2 / (A_a + A_b) of a rest stencil (dimensionless), k = (3 D / 4) times it.
template <typename T>
T strip_weight(const Eigen::Matrix<T, 12, 1>& x) {
  using Vector3 = Eigen::Matrix<T, 3, 1>;
  using std::sqrt;
  const Vector3 x0 = x.template segment<3>(0), x1 = x.template segment<3>(3), x2 = x.template segment<3>(6),
                x3 = x.template segment<3>(9);
  const Vector3 edge = x1 - x0;
  const T area = 0.5 * (sqrt(edge.cross(x2 - x0).squaredNorm()) + sqrt((x0 - x1).cross(x3 - x1).squaredNorm()));
  return edge.squaredNorm() / area;
}

/// theta - theta_rest in (-pi, pi]: a hinge that folds through a flat-back state keeps its meaning.
double bend_angle(double theta, double rest_angle) { return std::remainder(theta - rest_angle, 2.0 * M_PI); }

}  // namespace

std::vector<HingeVertices> mesh_hinges(const Faces& faces, std::vector<std::array<int, 2>>* hinge_faces) {
  // Directed edge (a, b) -> the triangle where it runs a -> b.
  std::map<std::pair<int, int>, int> face_of;
  std::map<std::pair<int, int>, int> uses;
  for (int f = 0; f < faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces(f, k), b = faces(f, (k + 1) % 3);
      face_of[{a, b}] = f;
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  auto opposite = [&](int face, int a, int b) {
    for (int k = 0; k < 3; ++k)
      if (faces(face, k) != a && faces(face, k) != b) return faces(face, k);
    return -1;
  };
  std::vector<HingeVertices> hinges;
  if (hinge_faces) hinge_faces->clear();
  for (const auto& [edge, face] : face_of) {
    const auto [a, b] = edge;
    if (a > b || uses[{a, b}] != 2) continue;  // each edge once; an edge of more or fewer triangles has no hinge
    const auto other = face_of.find({b, a});
    if (other == face_of.end()) continue;  // the two triangles disagree in orientation
    hinges.push_back({a, b, opposite(face, a, b), opposite(other->second, a, b)});
    if (hinge_faces) hinge_faces->push_back({face, other->second});
  }
  return hinges;
}

double bending_modulus(double shear_modulus_mpa, double thickness_mm) {
  return shear_modulus_mpa * thickness_mm * thickness_mm * thickness_mm / 3.0;
}

double dihedral_angle(const Vector12d& x) {
  const Eigen::Vector3d x0 = x.segment<3>(0), x1 = x.segment<3>(3), x2 = x.segment<3>(6), x3 = x.segment<3>(9);
  const Eigen::Vector3d edge = x1 - x0;
  const Eigen::Vector3d normal_a = edge.cross(x2 - x0);
  const Eigen::Vector3d normal_b = (x0 - x1).cross(x3 - x1);
  return std::atan2(normal_a.cross(normal_b).dot(edge) / edge.norm(), normal_a.dot(normal_b));
}

RestHinge make_rest_hinge(const Vector12d& rest, double bending_modulus_nmm) {
  RestHinge hinge;
  hinge.modulus = bending_modulus_nmm;
  hinge.rest_angle = dihedral_angle(rest);
  // A sliver pair of no area would make k unbounded: such a hinge carries no bending.
  const double weight = strip_weight(rest);
  hinge.stiffness = std::isfinite(weight) && std::isfinite(hinge.rest_angle) ? 0.75 * bending_modulus_nmm * weight : 0.0;
  return hinge;
}

double hinge_energy(const RestHinge& rest, const Vector12d& x) {
  const double bend = bend_angle(dihedral_angle(x), rest.rest_angle);
  return rest.stiffness * bend * bend;
}

void hinge_energy_gradient_hessian(const RestHinge& rest, const Vector12d& x, double& energy, Vector12d& gradient,
                                   Matrix12d& hessian, bool project_to_psd) {
  const double bend = bend_angle(dihedral_angle(x), rest.rest_angle);
  energy = rest.stiffness * bend * bend;
  const Vector12d angle_gradient = dihedral_angle_gradient(x);
  gradient = 2.0 * rest.stiffness * bend * angle_gradient;
  hessian = 2.0 * rest.stiffness * angle_gradient * angle_gradient.transpose();
  if (project_to_psd || bend == 0.0) return;
  // The angle's Hessian: forward-mode derivatives of its gradient (Eigen's AutoDiff, 12 directions).
  using Dual = Eigen::AutoDiffScalar<Vector12d>;
  Eigen::Matrix<Dual, 12, 1> dual_x;
  for (int i = 0; i < 12; ++i) dual_x[i] = Dual(x[i], 12, i);
  const Eigen::Matrix<Dual, 12, 1> dual_gradient = dihedral_angle_gradient(dual_x);
  Matrix12d angle_hessian;
  for (int i = 0; i < 12; ++i) angle_hessian.row(i) = dual_gradient[i].derivatives().transpose();
  hessian += 2.0 * rest.stiffness * bend * 0.5 * (angle_hessian + angle_hessian.transpose());
}

Vector12d hinge_energy_gradient(const RestHinge& rest, const Vector12d& x) {
  const double bend = bend_angle(dihedral_angle(x), rest.rest_angle);
  return 2.0 * rest.stiffness * bend * dihedral_angle_gradient(x);
}

Matrix12d hinge_mixed_derivative(const RestHinge& rest_hinge, const Vector12d& rest, const Vector12d& x) {
  // gradient_x = 2 k(X) (theta(x) - theta_rest(X)) grad theta(x), so its derivative in X is
  // 2 grad theta(x) [(theta - theta_rest) grad k(X) - k grad theta_rest(X)]^T.
  if (rest_hinge.stiffness == 0.0) return Matrix12d::Zero();
  const double bend = bend_angle(dihedral_angle(x), rest_hinge.rest_angle);
  using Dual = Eigen::AutoDiffScalar<Vector12d>;
  Eigen::Matrix<Dual, 12, 1> dual_rest;
  for (int i = 0; i < 12; ++i) dual_rest[i] = Dual(rest[i], 12, i);
  const Vector12d stiffness_gradient = 0.75 * rest_hinge.modulus * strip_weight(dual_rest).derivatives();
  const Vector12d rest_term = bend * stiffness_gradient - rest_hinge.stiffness * dihedral_angle_gradient(rest);
  return 2.0 * dihedral_angle_gradient(x) * rest_term.transpose();
}

}  // namespace balloon::fem
