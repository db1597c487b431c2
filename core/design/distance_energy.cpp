#include "design/distance_energy.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

using Matrix3d = Eigen::Matrix3d;
using Vector3d = Eigen::Vector3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

Matrix3d cross_matrix(const Vector3d& v) {
  Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// Wraps an angle difference into (-pi, pi] so a hinge folding through +-pi does not jump by 2 pi.
double wrap_angle(double a) {
  constexpr double PI = std::numbers::pi;
  while (a > PI) a -= 2.0 * PI;
  while (a <= -PI) a += 2.0 * PI;
  return a;
}

/// The dihedral angle as a function of u = (NA, NB, e): theta = atan2((NA x NB).e/|e|, NA.NB), with
/// NA = e x a, NB = b x e the (area-weighted) face normals, e = x1 - x0, a = x2 - x0, b = x3 - x0.
/// Splitting through u keeps every derivative short: NA and NB are bilinear in the positions, so their
/// second derivatives are constant (see hinge_second_order_term).
struct HingeFrame {
  Vector3d e, a, b, na, nb;
  double x = 0.0, y = 0.0, rho = 0.0;
  bool degenerate = false;

  HingeFrame(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2, const Vector3d& x3) {
    e = x1 - x0;
    a = x2 - x0;
    b = x3 - x0;
    na = e.cross(a);
    nb = b.cross(e);
    const double le = e.norm();
    x = na.dot(nb);
    y = le > 0.0 ? na.cross(nb).dot(e) / le : 0.0;
    rho = x * x + y * y;
    // |NA|^2 |NB|^2 = rho: below this the normals are numerically meaningless.
    const double scale = e.squaredNorm() * (a.squaredNorm() + b.squaredNorm());
    degenerate = !(le > 0.0) || !(rho > 1e-28 * scale * scale);
  }
  double angle() const { return std::atan2(y, x); }
};

/// d(NA, NB, e)/d(x0, x1, x2, x3): 9 by 12.
Eigen::Matrix<double, 9, 12> hinge_jacobian(const HingeFrame& h) {
  Eigen::Matrix<double, 9, 12> j = Eigen::Matrix<double, 9, 12>::Zero();
  const Matrix3d ce = cross_matrix(h.e), ca = cross_matrix(h.a), cb = cross_matrix(h.b);
  // dNA = -[a]x de + [e]x da, de = dx1 - dx0, da = dx2 - dx0.
  j.block<3, 3>(0, 0) = ca - ce;
  j.block<3, 3>(0, 3) = -ca;
  j.block<3, 3>(0, 6) = ce;
  // dNB = -[e]x db + [b]x de, db = dx3 - dx0.
  j.block<3, 3>(3, 0) = ce - cb;
  j.block<3, 3>(3, 3) = cb;
  j.block<3, 3>(3, 9) = -ce;
  j.block<3, 3>(6, 0) = -Matrix3d::Identity();
  j.block<3, 3>(6, 3) = Matrix3d::Identity();
  return j;
}

/// Gradient (9) of theta with respect to u = (NA, NB, e), and optionally its 9x9 Hessian.
void angle_derivatives_in_u(const HingeFrame& h, Eigen::Matrix<double, 9, 1>& g,
                            Eigen::Matrix<double, 9, 9>* hess) {
  const double le = h.e.norm();
  const Vector3d eh = h.e / le;
  const Vector3d w = h.na.cross(h.nb);
  const double wn = w.dot(eh);
  const Matrix3d p = Matrix3d::Identity() - eh * eh.transpose();

  Eigen::Matrix<double, 9, 1> gx, gy;
  gx << h.nb, h.na, Vector3d::Zero();
  gy << h.nb.cross(eh), eh.cross(h.na), p * w / le;
  const double rho = h.rho;
  const double tx = -h.y / rho, ty = h.x / rho;
  g = tx * gx + ty * gy;
  if (!hess) return;

  const double rho2 = rho * rho;
  const double txx = 2.0 * h.x * h.y / rho2, tyy = -txx, txy = (h.y * h.y - h.x * h.x) / rho2;
  Eigen::Matrix<double, 9, 9>& hu = *hess;
  hu = txx * gx * gx.transpose() + tyy * gy * gy.transpose() +
       txy * (gx * gy.transpose() + gy * gx.transpose());
  // Second derivatives of x = NA.NB and y = (NA x NB).e/|e| with respect to u.
  Eigen::Matrix<double, 9, 9> hy = Eigen::Matrix<double, 9, 9>::Zero();
  hy.block<3, 3>(0, 3) = -cross_matrix(eh);
  hy.block<3, 3>(0, 6) = cross_matrix(h.nb) * p / le;
  hy.block<3, 3>(3, 6) = -cross_matrix(h.na) * p / le;
  hy.block<3, 3>(6, 6) =
      -(w * eh.transpose() + eh * w.transpose() + wn * (Matrix3d::Identity() - 3.0 * eh * eh.transpose())) /
      (le * le);
  hy.block<3, 3>(3, 0) = hy.block<3, 3>(0, 3).transpose();
  hy.block<3, 3>(6, 0) = hy.block<3, 3>(0, 6).transpose();
  hy.block<3, 3>(6, 3) = hy.block<3, 3>(3, 6).transpose();
  hu += ty * hy;
  hu.block<3, 3>(0, 3) += tx * Matrix3d::Identity();
  hu.block<3, 3>(3, 0) += tx * Matrix3d::Identity();
}

/// sum_k g_k d^2 u_k / dx^2 for the bilinear NA = e x a and NB = b x e (12x12, constant in x).
/// g.(e x a) = e^T (-[g]x) a, so its Hessian couples the vertex blocks with the signs of e, a, b.
Matrix12d hinge_second_order_term(const Eigen::Matrix<double, 9, 1>& g) {
  Matrix12d out = Matrix12d::Zero();
  constexpr double SIGN_E[4] = {-1.0, 1.0, 0.0, 0.0};
  constexpr double SIGN_A[4] = {-1.0, 0.0, 1.0, 0.0};
  constexpr double SIGN_B[4] = {-1.0, 0.0, 0.0, 1.0};
  const Matrix3d ma = -cross_matrix(g.segment<3>(0));  // NA = e x a: e^T ma a
  const Matrix3d mb = -cross_matrix(g.segment<3>(3));  // NB = b x e: b^T mb e
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 4; ++k) {
      Matrix3d block = SIGN_E[i] * SIGN_A[k] * ma + SIGN_A[i] * SIGN_E[k] * ma.transpose() +
                       SIGN_B[i] * SIGN_E[k] * mb + SIGN_E[i] * SIGN_B[k] * mb.transpose();
      out.block<3, 3>(3 * i, 3 * k) = block;
    }
  }
  return out;
}

/// Clamps negative eigenvalues of a small symmetric matrix to zero.
template <int N>
Eigen::Matrix<double, N, N> project_psd(const Eigen::Matrix<double, N, N>& m) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(m);
  Eigen::Matrix<double, N, 1> lambda = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

Vector3d vertex(Eigen::Ref<const Eigen::VectorXd> x, int v) { return x.segment<3>(3 * v); }

template <int N>
void scatter(const Eigen::Matrix<double, N, N>& local, const int* vertices, int dof_offset,
             std::vector<Eigen::Triplet<double>>& triplets) {
  constexpr int NV = N / 3;
  for (int i = 0; i < NV; ++i) {
    for (int k = 0; k < NV; ++k) {
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          const double value = local(3 * i + a, 3 * k + b);
          if (value != 0.0) {
            triplets.emplace_back(dof_offset + 3 * vertices[i] + a, dof_offset + 3 * vertices[k] + b, value);
          }
        }
      }
    }
  }
}

}  // namespace

double dihedral_angle(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2, const Vector3d& x3) {
  return HingeFrame(x0, x1, x2, x3).angle();
}

Vector12d dihedral_angle_gradient(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                                  const Vector3d& x3) {
  const HingeFrame h(x0, x1, x2, x3);
  if (h.degenerate) return Vector12d::Zero();
  Eigen::Matrix<double, 9, 1> gu;
  angle_derivatives_in_u(h, gu, nullptr);
  return hinge_jacobian(h).transpose() * gu;
}

Matrix12d dihedral_angle_hessian(const Vector3d& x0, const Vector3d& x1, const Vector3d& x2,
                                 const Vector3d& x3) {
  const HingeFrame h(x0, x1, x2, x3);
  if (h.degenerate) return Matrix12d::Zero();
  Eigen::Matrix<double, 9, 1> gu;
  Eigen::Matrix<double, 9, 9> hu;
  angle_derivatives_in_u(h, gu, &hu);
  const Eigen::Matrix<double, 9, 12> j = hinge_jacobian(h);
  Matrix12d out = j.transpose() * hu * j + hinge_second_order_term(gu);
  return 0.5 * (out + out.transpose());
}

DistanceEnergy::DistanceEnergy(const Positions& reference, const Faces& faces, double k_length,
                               double k_bending)
    : m_vertex_count(static_cast<int>(reference.rows())), m_k_length(k_length), m_k_bending(k_bending) {
  if (!(k_length >= 0.0) || !(k_bending >= 0.0)) {
    throw std::invalid_argument("DistanceEnergy: stiffnesses must be >= 0");
  }
  const EdgeTopology topology = build_edge_topology(faces, m_vertex_count);  // throws if non-manifold
  // Interior edges first so that hinge h is edge h. Face edge_faces(e, 0) runs v0 -> v1; the stencil
  // needs the other face to run v1 -> v0 (consistent orientation), which the topology does not check.
  m_edges.resize(topology.edges.rows(), 4);
  int row = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (Eigen::Index e = 0; e < topology.edges.rows(); ++e) {
      const int v0 = topology.edges(e, 0), v1 = topology.edges(e, 1), f1 = topology.edge_faces(e, 1);
      if ((f1 >= 0) != (pass == 0)) continue;
      if (f1 >= 0) {
        bool reversed = false;
        for (int k = 0; k < 3; ++k) reversed |= faces(f1, k) == v1 && faces(f1, (k + 1) % 3) == v0;
        if (!reversed) {
          throw std::invalid_argument("DistanceEnergy: inconsistent orientation at edge (" + std::to_string(v0) +
                                      ", " + std::to_string(v1) + ")");
        }
      }
      m_edges.row(row++) << v0, v1, topology.edge_opposite(e, 0), topology.edge_opposite(e, 1);
    }
    if (pass == 0) m_hinge_count = row;
  }

  const Eigen::Map<const Eigen::VectorXd> xr(reference.data(), reference.size());
  m_rest_lengths.resize(edge_count());
  m_rest_angles.resize(m_hinge_count);
  for (int e = 0; e < edge_count(); ++e) {
    const double l0 = (vertex(xr, m_edges(e, 1)) - vertex(xr, m_edges(e, 0))).norm();
    if (!(l0 > 0.0)) {
      throw std::invalid_argument("DistanceEnergy: reference edge " + std::to_string(e) + " has zero length");
    }
    m_rest_lengths(e) = l0;
    if (e < m_hinge_count) {
      m_rest_angles(e) = dihedral_angle(vertex(xr, m_edges(e, 0)), vertex(xr, m_edges(e, 1)),
                                        vertex(xr, m_edges(e, 2)), vertex(xr, m_edges(e, 3)));
    }
  }
}

double DistanceEnergy::value(Eigen::Ref<const Eigen::VectorXd> x) const { return value_parts(x).sum(); }

Eigen::Vector2d DistanceEnergy::value_parts(Eigen::Ref<const Eigen::VectorXd> x) const {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("DistanceEnergy: x has the wrong size");
  Eigen::Vector2d parts = Eigen::Vector2d::Zero();
  if (m_k_length > 0.0) {
    for (int e = 0; e < edge_count(); ++e) {
      const double l0 = m_rest_lengths(e);
      const double l = (vertex(x, m_edges(e, 1)) - vertex(x, m_edges(e, 0))).norm();
      parts(0) += m_k_length * (l - l0) * (l - l0) / l0;  // = k_l (1 - l/l0)^2 l0
    }
  }
  if (m_k_bending > 0.0) {
    for (int e = 0; e < m_hinge_count; ++e) {
      const double theta = dihedral_angle(vertex(x, m_edges(e, 0)), vertex(x, m_edges(e, 1)),
                                          vertex(x, m_edges(e, 2)), vertex(x, m_edges(e, 3)));
      const double d = wrap_angle(theta - m_rest_angles(e));
      parts(1) += m_k_bending * d * d * m_rest_lengths(e);
    }
  }
  return parts;
}

void DistanceEnergy::gradient(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& gradient) const {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("DistanceEnergy: x has the wrong size");
  gradient.setZero(3 * m_vertex_count);
  if (m_k_length > 0.0) {
    for (int e = 0; e < edge_count(); ++e) {
      const int v0 = m_edges(e, 0), v1 = m_edges(e, 1);
      const Vector3d d = vertex(x, v1) - vertex(x, v0);
      const double l = d.norm(), l0 = m_rest_lengths(e);
      if (!(l > 0.0)) continue;
      const Vector3d g = 2.0 * m_k_length * (l - l0) / l0 * d / l;
      gradient.segment<3>(3 * v1) += g;
      gradient.segment<3>(3 * v0) -= g;
    }
  }
  if (m_k_bending > 0.0) {
    for (int e = 0; e < m_hinge_count; ++e) {
      const int* v = &m_edges(e, 0);
      const HingeFrame h(vertex(x, v[0]), vertex(x, v[1]), vertex(x, v[2]), vertex(x, v[3]));
      if (h.degenerate) continue;
      Eigen::Matrix<double, 9, 1> gu;
      angle_derivatives_in_u(h, gu, nullptr);
      const double d = wrap_angle(h.angle() - m_rest_angles(e));
      const Vector12d g = 2.0 * m_k_bending * m_rest_lengths(e) * d * (hinge_jacobian(h).transpose() * gu);
      for (int i = 0; i < 4; ++i) gradient.segment<3>(3 * v[i]) += g.segment<3>(3 * i);
    }
  }
}

void DistanceEnergy::hessian_triplets(Eigen::Ref<const Eigen::VectorXd> x,
                                      std::vector<Eigen::Triplet<double>>& triplets, DistanceHessian kind,
                                      int dof_offset) const {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("DistanceEnergy: x has the wrong size");
  triplets.reserve(triplets.size() + hessian_entry_count());
  if (m_k_length > 0.0) {
    for (int e = 0; e < edge_count(); ++e) {
      const int* v = &m_edges(e, 0);
      const Vector3d d = vertex(x, v[1]) - vertex(x, v[0]);
      const double l = d.norm(), l0 = m_rest_lengths(e);
      if (!(l > 0.0)) continue;
      const Vector3d n = d / l;
      // E = (k/l0)(l - l0)^2: H = 2k/l0 [n n^T + (l - l0)/l (I - n n^T)] on the (x1 - x0) block.
      double along = 2.0 * m_k_length / l0;
      double across = along * (l - l0) / l;
      if (kind == DistanceHessian::GaussNewton) across = 0.0;
      if (kind == DistanceHessian::ProjectedExact) across = std::max(across, 0.0);
      const Matrix3d block = along * n * n.transpose() + across * (Matrix3d::Identity() - n * n.transpose());
      Matrix6d local;
      local << block, -block, -block, block;
      scatter<6>(local, v, dof_offset, triplets);
    }
  }
  if (m_k_bending > 0.0) {
    for (int e = 0; e < m_hinge_count; ++e) {
      const int* v = &m_edges(e, 0);
      const HingeFrame h(vertex(x, v[0]), vertex(x, v[1]), vertex(x, v[2]), vertex(x, v[3]));
      if (h.degenerate) continue;
      const double w = 2.0 * m_k_bending * m_rest_lengths(e);
      Eigen::Matrix<double, 9, 1> gu;
      Eigen::Matrix<double, 9, 9> hu;
      const Eigen::Matrix<double, 9, 12> j = hinge_jacobian(h);
      Matrix12d local;
      if (kind == DistanceHessian::GaussNewton) {
        angle_derivatives_in_u(h, gu, nullptr);
        const Vector12d g = j.transpose() * gu;
        local = w * g * g.transpose();
      } else {
        angle_derivatives_in_u(h, gu, &hu);
        const Vector12d g = j.transpose() * gu;
        Matrix12d h_theta = j.transpose() * hu * j + hinge_second_order_term(gu);
        h_theta = 0.5 * (h_theta + h_theta.transpose());
        const double d = wrap_angle(h.angle() - m_rest_angles(e));
        local = w * (g * g.transpose() + d * h_theta);
        if (kind == DistanceHessian::ProjectedExact) local = project_psd<12>(local);
      }
      scatter<12>(local, v, dof_offset, triplets);
    }
  }
}

size_t DistanceEnergy::hessian_entry_count() const {
  return (m_k_length > 0.0 ? 36 * static_cast<size_t>(edge_count()) : 0) +
         (m_k_bending > 0.0 ? 144 * static_cast<size_t>(m_hinge_count) : 0);
}

Eigen::SparseMatrix<double> DistanceEnergy::hessian(Eigen::Ref<const Eigen::VectorXd> x,
                                                    DistanceHessian kind) const {
  std::vector<Eigen::Triplet<double>> triplets;
  hessian_triplets(x, triplets, kind, 0);
  Eigen::SparseMatrix<double> h(3 * m_vertex_count, 3 * m_vertex_count);
  h.setFromTriplets(triplets.begin(), triplets.end());
  return h;
}

int DistanceEnergy::residual_count() const {
  return (m_k_length > 0.0 ? edge_count() : 0) + (m_k_bending > 0.0 ? m_hinge_count : 0);
}

void DistanceEnergy::residuals(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& residuals) const {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("DistanceEnergy: x has the wrong size");
  residuals.resize(residual_count());
  int row = 0;
  if (m_k_length > 0.0) {
    for (int e = 0; e < edge_count(); ++e) {
      const double l0 = m_rest_lengths(e);
      const double l = (vertex(x, m_edges(e, 1)) - vertex(x, m_edges(e, 0))).norm();
      residuals(row++) = std::sqrt(m_k_length * l0) * (1.0 - l / l0);
    }
  }
  if (m_k_bending > 0.0) {
    for (int e = 0; e < m_hinge_count; ++e) {
      const double theta = dihedral_angle(vertex(x, m_edges(e, 0)), vertex(x, m_edges(e, 1)),
                                          vertex(x, m_edges(e, 2)), vertex(x, m_edges(e, 3)));
      residuals(row++) = std::sqrt(m_k_bending * m_rest_lengths(e)) * wrap_angle(theta - m_rest_angles(e));
    }
  }
}

void DistanceEnergy::residual_jacobian_triplets(Eigen::Ref<const Eigen::VectorXd> x,
                                                std::vector<Eigen::Triplet<double>>& triplets,
                                                int dof_offset) const {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("DistanceEnergy: x has the wrong size");
  triplets.reserve(triplets.size() + (m_k_length > 0.0 ? 6 * static_cast<size_t>(edge_count()) : 0) +
                   (m_k_bending > 0.0 ? 12 * static_cast<size_t>(m_hinge_count) : 0));
  int row = 0;
  if (m_k_length > 0.0) {
    for (int e = 0; e < edge_count(); ++e, ++row) {
      const int v0 = m_edges(e, 0), v1 = m_edges(e, 1);
      const Vector3d d = vertex(x, v1) - vertex(x, v0);
      const double l = d.norm(), l0 = m_rest_lengths(e);
      if (!(l > 0.0)) continue;
      // r = sqrt(k l0) (1 - l/l0): dr/dx1 = -sqrt(k l0)/l0 * d/l.
      const Vector3d g = -std::sqrt(m_k_length * l0) / l0 * d / l;
      for (int a = 0; a < 3; ++a) {
        triplets.emplace_back(row, dof_offset + 3 * v1 + a, g(a));
        triplets.emplace_back(row, dof_offset + 3 * v0 + a, -g(a));
      }
    }
  }
  if (m_k_bending > 0.0) {
    for (int e = 0; e < m_hinge_count; ++e, ++row) {
      const int* v = &m_edges(e, 0);
      const Vector12d g =
          std::sqrt(m_k_bending * m_rest_lengths(e)) *
          dihedral_angle_gradient(vertex(x, v[0]), vertex(x, v[1]), vertex(x, v[2]), vertex(x, v[3]));
      for (int i = 0; i < 4; ++i) {
        for (int a = 0; a < 3; ++a) triplets.emplace_back(row, dof_offset + 3 * v[i] + a, g(3 * i + a));
      }
    }
  }
}

}  // namespace balloon
