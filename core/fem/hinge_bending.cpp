#include "fem/hinge_bending.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <utility>

#include <unsupported/Eigen/AutoDiff>

namespace balloon::fem {
namespace {

/// What the angle, its gradient and its Hessian share: the hinge edge and the two triangles' normals.
struct HingeTerms {
  Eigen::Vector3d edge, unit_edge, normal_a, normal_b;
  double length;
};

HingeTerms hinge_terms(const Vector12d& x) {
  HingeTerms t;
  const Eigen::Vector3d x0 = x.segment<3>(0), x1 = x.segment<3>(3), x2 = x.segment<3>(6), x3 = x.segment<3>(9);
  t.edge = x1 - x0;
  t.normal_a = t.edge.cross(x2 - x0);
  t.normal_b = (x0 - x1).cross(x3 - x1);
  t.length = t.edge.norm();
  t.unit_edge = t.edge / t.length;
  return t;
}

double dihedral_angle(const HingeTerms& t) {
  return std::atan2(t.normal_a.cross(t.normal_b).dot(t.edge) / t.length, t.normal_a.dot(t.normal_b));
}

/// Gradient of the dihedral angle in closed form (Bridson, Marino and Fedkiw, "Simulation of clothing with
/// folds and wrinkles", SCA 2003): each triangle's normal direction, weighted by the lever arms of its
/// vertices about the hinge.
Vector12d dihedral_angle_gradient(const Vector12d& x, const HingeTerms& t) {
  using Eigen::Vector3d;
  const Vector3d x0 = x.segment<3>(0), x1 = x.segment<3>(3), x2 = x.segment<3>(6), x3 = x.segment<3>(9);
  const Vector3d a = t.normal_a / t.normal_a.squaredNorm();
  const Vector3d b = t.normal_b / t.normal_b.squaredNorm();
  Vector12d g;
  g.segment<3>(0) = -((x2 - x1).dot(t.unit_edge) * a + (x3 - x1).dot(t.unit_edge) * b);
  g.segment<3>(3) = (x2 - x0).dot(t.unit_edge) * a + (x3 - x0).dot(t.unit_edge) * b;
  g.segment<3>(6) = -t.length * a;
  g.segment<3>(9) = -t.length * b;
  return g;
}

Vector12d dihedral_angle_gradient(const Vector12d& x) { return dihedral_angle_gradient(x, hinge_terms(x)); }

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// A 3x12 Jacobian with one 3x3 block per stencil vertex.
using Jacobian3x12 = Eigen::Matrix<double, 3, 12>;
Jacobian3x12 blocks(const Eigen::Matrix3d& b0, const Eigen::Matrix3d& b1, const Eigen::Matrix3d& b2,
                    const Eigen::Matrix3d& b3) {
  Jacobian3x12 j;
  j << b0, b1, b2, b3;
  return j;
}

/// The dihedral angle's Hessian: the derivative of dihedral_angle_gradient's expressions, term by term
/// (product and quotient rules on its normals, lever arms and edge length). It replaced forward-mode
/// automatic differentiation of that gradient (12 directions carried through every operation).
Matrix12d dihedral_angle_hessian(const Vector12d& x, const HingeTerms& t) {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  const Vector3d to_a = x.segment<3>(6) - x.segment<3>(0), to_b = x.segment<3>(9) - x.segment<3>(3);
  const Matrix3d I = Matrix3d::Identity(), O = Matrix3d::Zero();

  // d(edge) = dx1 - dx0; the unit edge and the length follow it.
  const Jacobian3x12 d_edge = blocks(-I, I, O, O);
  const Jacobian3x12 d_unit_edge = (I - t.unit_edge * t.unit_edge.transpose()) / t.length * d_edge;
  const Eigen::Matrix<double, 1, 12> d_length = t.unit_edge.transpose() * d_edge;
  // normal_a = edge x (x2 - x0), normal_b = -edge x (x3 - x1).
  const Matrix3d edge_x = cross_matrix(t.edge), to_a_x = cross_matrix(to_a), to_b_x = cross_matrix(to_b);
  const Jacobian3x12 d_normal_a = blocks(to_a_x - edge_x, -to_a_x, edge_x, O);
  const Jacobian3x12 d_normal_b = blocks(-to_b_x, to_b_x + edge_x, O, -edge_x);
  // a = n / |n|^2: da = (I - 2 n n^T / |n|^2) dn / |n|^2.
  auto scaled_normal = [&](const Vector3d& n, const Jacobian3x12& dn, Vector3d& value, Jacobian3x12& derivative) {
    const double nn = n.squaredNorm();
    value = n / nn;
    derivative = (I - 2.0 * n * n.transpose() / nn) / nn * dn;
  };
  Vector3d a, b;
  Jacobian3x12 da, db;
  scaled_normal(t.normal_a, d_normal_a, a, da);
  scaled_normal(t.normal_b, d_normal_b, b, db);
  // Lever arm (p - q) . unit_edge of stencil vertices p, q, and its derivative.
  auto lever = [&](int p, int q, double& value, Eigen::Matrix<double, 1, 12>& derivative) {
    const Vector3d arm = x.segment<3>(3 * p) - x.segment<3>(3 * q);
    value = arm.dot(t.unit_edge);
    derivative = arm.transpose() * d_unit_edge;
    derivative.segment<3>(3 * p) += t.unit_edge.transpose();
    derivative.segment<3>(3 * q) -= t.unit_edge.transpose();
  };
  double a_from_1, b_from_1, a_from_0, b_from_0;
  Eigen::Matrix<double, 1, 12> d_a_from_1, d_b_from_1, d_a_from_0, d_b_from_0;
  lever(2, 1, a_from_1, d_a_from_1);
  lever(3, 1, b_from_1, d_b_from_1);
  lever(2, 0, a_from_0, d_a_from_0);
  lever(3, 0, b_from_0, d_b_from_0);

  Matrix12d h;
  h.middleRows<3>(0) = -(a * d_a_from_1 + a_from_1 * da + b * d_b_from_1 + b_from_1 * db);
  h.middleRows<3>(3) = a * d_a_from_0 + a_from_0 * da + b * d_b_from_0 + b_from_0 * db;
  h.middleRows<3>(6) = -(a * d_length + t.length * da);
  h.middleRows<3>(9) = -(b * d_length + t.length * db);
  return h;
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

double dihedral_angle(const Vector12d& x) { return dihedral_angle(hinge_terms(x)); }

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
  const HingeTerms terms = hinge_terms(x);
  const double bend = bend_angle(dihedral_angle(terms), rest.rest_angle);
  energy = rest.stiffness * bend * bend;
  const Vector12d angle_gradient = dihedral_angle_gradient(x, terms);
  gradient = 2.0 * rest.stiffness * bend * angle_gradient;
  hessian = 2.0 * rest.stiffness * angle_gradient * angle_gradient.transpose();
  if (project_to_psd || bend == 0.0) return;
  const Matrix12d angle_hessian = dihedral_angle_hessian(x, terms);
  hessian += 2.0 * rest.stiffness * bend * 0.5 * (angle_hessian + angle_hessian.transpose());
}

Vector12d hinge_energy_gradient(const RestHinge& rest, const Vector12d& x) {
  const HingeTerms terms = hinge_terms(x);
  const double bend = bend_angle(dihedral_angle(terms), rest.rest_angle);
  return 2.0 * rest.stiffness * bend * dihedral_angle_gradient(x, terms);
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
