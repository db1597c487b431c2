#include "design/distance_energy.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <random>

#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

using design_test::make_bumpy_sphere;
using design_test::make_icosphere;

Eigen::VectorXd perturbed(const TriMesh& mesh, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Eigen::VectorXd x = flat(mesh.vertices);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += u(rng);
  return x;
}

Eigen::VectorXd fd_gradient(const DistanceEnergy& energy, const Eigen::VectorXd& x, double h) {
  Eigen::VectorXd g(x.size());
  Eigen::VectorXd xp = x;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    xp(i) = x(i) + h;
    const double ep = energy.value(xp);
    xp(i) = x(i) - h;
    const double em = energy.value(xp);
    xp(i) = x(i);
    g(i) = (ep - em) / (2 * h);
  }
  return g;
}

Eigen::MatrixXd fd_hessian(const DistanceEnergy& energy, const Eigen::VectorXd& x, double h) {
  Eigen::MatrixXd hess(x.size(), x.size());
  Eigen::VectorXd xp = x, gp, gm;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    xp(i) = x(i) + h;
    energy.gradient(xp, gp);
    xp(i) = x(i) - h;
    energy.gradient(xp, gm);
    xp(i) = x(i);
    hess.col(i) = (gp - gm) / (2 * h);
  }
  return hess;
}

TEST(DihedralAngle, SignAndValueOnKnownHinges) {
  const Eigen::Vector3d x0(0, 0, 0), x1(1, 0, 0);
  // Flat hinge: (x0, x1, x2) and (x1, x0, x3) both with normal +z.
  EXPECT_NEAR(dihedral_angle(x0, x1, {0.5, 1, 0}, {0.5, -1, 0}), 0.0, 1e-14);
  // Folding the second wing down (away from the normal side) makes a convex ridge of 90 degrees.
  EXPECT_NEAR(dihedral_angle(x0, x1, {0.5, 1, 0}, {0.5, 0, -1}), M_PI / 2, 1e-12);
  EXPECT_NEAR(dihedral_angle(x0, x1, {0.5, 1, 0}, {0.5, 0, 1}), -M_PI / 2, 1e-12);
  // Every hinge of a sphere is convex.
  const TriMesh sphere = make_icosphere(2, 1.0);
  DistanceEnergy energy(sphere.vertices, sphere.faces);
  EXPECT_GT(energy.rest_angles().minCoeff(), 0.05);
}

TEST(DihedralAngle, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int checked = 0;
  // Random stencils, plus near-flat (theta ~ 0) and near-folded (theta ~ +-pi) ones.
  for (int trial = 0; trial < 30; ++trial) {
    Vector12d x;
    for (int i = 0; i < 12; ++i) x(i) = u(rng);
    if (trial % 3 == 1) x(11) = 1e-3 * u(rng), x(8) = 1e-3 * u(rng), x(2) = x(5) = 0.0;
    if (trial % 3 == 2) x.segment<3>(9) = x.segment<3>(6) + 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    auto angle = [](const Vector12d& y) {
      return dihedral_angle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9));
    };
    auto grad = [](const Vector12d& y) {
      return dihedral_angle_gradient(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9));
    };
    const Vector12d g = grad(x);
    const Matrix12d hess =
        dihedral_angle_hessian(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9));
    Vector12d g_fd;
    Matrix12d h_fd;
    const double h = 1e-6;
    bool wraps = false;
    for (int i = 0; i < 12; ++i) {
      Vector12d xp = x, xm = x;
      xp(i) += h;
      xm(i) -= h;
      const double dp = angle(xp), dm = angle(xm);
      wraps |= std::abs(dp - dm) > 1.0;
      g_fd(i) = (dp - dm) / (2 * h);
      h_fd.col(i) = (grad(xp) - grad(xm)) / (2 * h);
    }
    if (wraps) continue;  // finite differences across the +-pi branch cut say nothing
    ASSERT_GT(g.norm(), 1e-3);
    ASSERT_GT(hess.norm(), 1e-3);
    EXPECT_LE((g - g_fd).norm(), 1e-6 * g.norm()) << "trial " << trial;
    EXPECT_LE((hess - h_fd).norm(), 1e-5 * hess.norm()) << "trial " << trial;
    EXPECT_LE((hess - hess.transpose()).norm(), 1e-12 * hess.norm());
    ++checked;
  }
  EXPECT_GE(checked, 25);
}

TEST(DistanceEnergy, ZeroAtReferenceAndInvariantToRigidMotion) {
  const TriMesh bumpy = make_bumpy_sphere(2, 40.0, 0.15);
  DistanceEnergy energy(bumpy.vertices, bumpy.faces, 1.0, 1.0);
  EXPECT_EQ(energy.edge_count(), 3 * bumpy.face_count() / 2);
  EXPECT_EQ(energy.hinge_count(), energy.edge_count());
  const Eigen::VectorXd x0 = flat(bumpy.vertices);
  EXPECT_NEAR(energy.value(x0), 0.0, 1e-20);
  Eigen::VectorXd g;
  energy.gradient(x0, g);
  EXPECT_LE(g.norm(), 1e-12);

  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Positions moved = bumpy.vertices;
  for (int i = 0; i < moved.rows(); ++i) moved.row(i) = (r * bumpy.vertices.row(i).transpose()).transpose() + Eigen::RowVector3d(5, -3, 12);
  EXPECT_NEAR(energy.value(flat(moved)), 0.0, 1e-18);

  // Non-rigid: a 1% uniform scaling gives sum k_l (0.01)^2 l0 for the length part and no bending change.
  Positions scaled = 1.01 * bumpy.vertices;
  const Eigen::Vector2d parts = energy.value_parts(flat(scaled));
  EXPECT_NEAR(parts(0), 1e-4 * energy.rest_lengths().sum(), 1e-9 * parts(0));
  EXPECT_NEAR(parts(1), 0.0, 1e-18);
}

void check_derivatives(const TriMesh& reference, const Eigen::VectorXd& x, double k_l, double k_b) {
  DistanceEnergy energy(reference.vertices, reference.faces, k_l, k_b);
  Eigen::VectorXd g;
  energy.gradient(x, g);
  const double scale = reference.vertices.cwiseAbs().maxCoeff();
  const Eigen::VectorXd g_fd = fd_gradient(energy, x, 1e-6 * scale);
  ASSERT_GT(g.norm(), 1e-6);
  EXPECT_LE((g - g_fd).norm(), 1e-6 * g.norm());

  const Eigen::MatrixXd h = Eigen::MatrixXd(energy.hessian(x, DistanceHessian::Exact));
  const Eigen::MatrixXd h_fd = fd_hessian(energy, x, 1e-6 * scale);
  ASSERT_GT(h.norm(), 1e-6);
  EXPECT_LE((h - h_fd).norm(), 1e-5 * h.norm());

  // Residuals: value = |r|^2, Jacobian against finite differences, Gauss-Newton = 2 J^T J.
  Eigen::VectorXd r;
  energy.residuals(x, r);
  EXPECT_NEAR(r.squaredNorm(), energy.value(x), 1e-12 * energy.value(x));
  std::vector<Eigen::Triplet<double>> jt;
  energy.residual_jacobian_triplets(x, jt);
  Eigen::SparseMatrix<double> j(energy.residual_count(), x.size());
  j.setFromTriplets(jt.begin(), jt.end());
  Eigen::MatrixXd j_fd(energy.residual_count(), x.size());
  Eigen::VectorXd xp = x, rp, rm;
  const double hstep = 1e-6 * scale;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    xp(i) = x(i) + hstep;
    energy.residuals(xp, rp);
    xp(i) = x(i) - hstep;
    energy.residuals(xp, rm);
    xp(i) = x(i);
    j_fd.col(i) = (rp - rm) / (2 * hstep);
  }
  const Eigen::MatrixXd jd(j);
  ASSERT_GT(jd.norm(), 1e-6);
  EXPECT_LE((jd - j_fd).norm(), 1e-6 * jd.norm());
  const Eigen::MatrixXd gn = Eigen::MatrixXd(energy.hessian(x, DistanceHessian::GaussNewton));
  EXPECT_LE((gn - 2.0 * jd.transpose() * jd).norm(), 1e-10 * gn.norm());
  EXPECT_LE((2.0 * jd.transpose() * r - g).norm(), 1e-10 * g.norm());

  // The projected Hessian is positive semi-definite.
  const Eigen::MatrixXd hp = Eigen::MatrixXd(energy.hessian(x, DistanceHessian::ProjectedExact));
  const double min_eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(hp).eigenvalues().minCoeff();
  EXPECT_GE(min_eig, -1e-10 * hp.norm());
}

TEST(DistanceEnergy, DerivativesOnPerturbedIcosphere) {
  const TriMesh sphere = make_icosphere(1, 30.0);
  check_derivatives(sphere, perturbed(sphere, 2.0, 1), 1.0, 1.0);
}

TEST(DistanceEnergy, DerivativesOnBumpyShape) {
  const TriMesh bumpy = make_bumpy_sphere(1, 30.0, 0.2);
  const TriMesh sphere = make_icosphere(1, 25.0);
  // Reference: the bumpy shape; current: a sphere with noise, far from the reference.
  check_derivatives(bumpy, perturbed(sphere, 1.0, 2), 1.0, 3.0);
}

TEST(DistanceEnergy, BendingOnlyRegularizer) {
  const TriMesh sphere = make_icosphere(1, 30.0);
  DistanceEnergy regularizer(sphere.vertices, sphere.faces, 0.0, 1.0);
  EXPECT_EQ(regularizer.residual_count(), regularizer.hinge_count());
  // Scaling does not bend: the regularizer leaves it free.
  Positions scaled = 1.3 * sphere.vertices;
  EXPECT_NEAR(regularizer.value(flat(scaled)), 0.0, 1e-20);
  check_derivatives(sphere, perturbed(sphere, 2.0, 3), 0.0, 1.0);
}

TEST(DistanceEnergy, GaussNewtonEqualsExactAtReference) {
  const TriMesh bumpy = make_bumpy_sphere(1, 30.0, 0.2);
  DistanceEnergy energy(bumpy.vertices, bumpy.faces);
  const Eigen::VectorXd x = flat(bumpy.vertices);
  const Eigen::MatrixXd exact(energy.hessian(x, DistanceHessian::Exact));
  const Eigen::MatrixXd gn(energy.hessian(x, DistanceHessian::GaussNewton));
  ASSERT_GT(exact.norm(), 1e-3);
  EXPECT_LE((exact - gn).norm(), 1e-12 * exact.norm());
}

TEST(DistanceEnergy, RejectsInconsistentOrientation) {
  TriMesh sphere = make_icosphere(0, 1.0);
  std::swap(sphere.faces(0, 0), sphere.faces(0, 1));
  EXPECT_THROW(DistanceEnergy(sphere.vertices, sphere.faces), std::invalid_argument);
}

}  // namespace
}  // namespace balloon
