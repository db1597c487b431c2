// The bending hinge against finite differences (gradient from the energy, Hessian from the gradient),
// the dihedral angle against geometry, and the model's sums: a uniformly scaled sphere carries no
// bending energy, and the assembled Hessian with hinges equals finite differences of the model gradient.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "core/central_differences.hpp"
#include "fem/assembly.hpp"
#include "fem/balloon_model.hpp"
#include "fem/hinge_bending.hpp"
#include "mesh/icosphere.hpp"

namespace balloon::fem {
namespace {

/// A hinge along x from the origin, its two wings at `fold` (rad) below the flat state on either side.
Vector12d tent(double fold, double wing = 1.0) {
  Vector12d x;
  x << 0, 0, 0, 1.2, 0, 0, 0.4, wing * std::cos(fold), -wing * std::sin(fold), 0.7, -wing * std::cos(fold),
      -wing * std::sin(fold);
  return x;
}

/// A Neo-Hookean (mu = 0.3 MPa) balloon of `mesh` with a uniform thickness.
BalloonModel neo_hookean_balloon(const TriMesh& mesh, double thickness_mm) {
  Material rubber;
  rubber.model = MaterialModel::NeoHookean;
  rubber.params = {0.3, 0, 0};
  return BalloonModel(mesh, rubber, std::vector<double>(static_cast<size_t>(mesh.face_count()), thickness_mm));
}

TEST(HingeBending, DihedralAngleIsZeroWhenFlatAndPositiveWhenConvex) {
  EXPECT_NEAR(dihedral_angle(tent(0.0)), 0.0, 1e-15);
  // Each wing tilted down by `fold`: the normals are 2 fold apart; a convex fold, as on a sphere.
  EXPECT_NEAR(dihedral_angle(tent(0.3)), 0.6, 1e-12);
  EXPECT_NEAR(dihedral_angle(tent(-0.2)), -0.4, 1e-12);
}

TEST(HingeBending, GradientAndHessianMatchCentralDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double fold : {0.0, 0.2, -0.5, 1.2}) {
    for (const double wing : {1.0, 1e-3}) {  // 1e-3: a sliver pair (angle ~0.1 degree at the edge)
      const RestHinge rest = make_rest_hinge(tent(0.1, wing), 0.02);
      Vector12d x = tent(fold, wing);
      for (int i = 0; i < 12; ++i) x[i] += 0.05 * wing * u(rng);
      double energy;
      Vector12d gradient;
      Matrix12d hessian;
      hinge_energy_gradient_hessian(rest, x, energy, gradient, hessian);
      EXPECT_NEAR(energy, hinge_energy(rest, x), 1e-15 * (1.0 + energy));
      EXPECT_LT((gradient - hinge_energy_gradient(rest, x)).norm(), 1e-12 * (1.0 + gradient.norm()));
      const double h = 1e-6 * wing;
      const Vector12d fd_gradient =
          test::central_difference_gradient([&](const Vector12d& y) { return hinge_energy(rest, y); }, x, h);
      const Matrix12d fd_hessian =
          test::central_difference_jacobian([&](const Vector12d& y) { return hinge_energy_gradient(rest, y); }, x, h);
      SCOPED_TRACE(testing::Message() << "fold " << fold << ", wing " << wing);
      EXPECT_LT((gradient - fd_gradient).norm(), 1e-6 * gradient.norm() + 1e-9);
      EXPECT_LT((hessian - fd_hessian).norm(), 1e-6 * hessian.norm() + 1e-9);
      EXPECT_LT((hessian - hessian.transpose()).norm(), 1e-12 * hessian.norm());
      // The projected Hessian is positive semi-definite.
      hinge_energy_gradient_hessian(rest, x, energy, gradient, hessian, true);
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix12d>(hessian).eigenvalues().minCoeff(), -1e-12 * hessian.norm());
    }
  }
}

TEST(HingeBending, MixedRestDerivativeMatchesCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double fold : {0.0, 0.3, -0.6}) {
    Vector12d rest = tent(0.1), x = tent(fold);
    for (int i = 0; i < 12; ++i) {
      rest[i] += 0.05 * u(rng);
      x[i] += 0.05 * u(rng);
    }
    const double modulus = 0.02;
    const Matrix12d mixed = hinge_mixed_derivative(make_rest_hinge(rest, modulus), rest, x);
    const Matrix12d fd = test::central_difference_jacobian(
        [&](const Vector12d& r) { return hinge_energy_gradient(make_rest_hinge(r, modulus), x); }, rest, 1e-6);
    EXPECT_LT((mixed - fd).norm(), 1e-6 * mixed.norm()) << "fold " << fold;
    EXPECT_GT(mixed.norm(), 0.0);
  }
}

TEST(HingeBending, StiffnessIsTheSheetsBendingModulusOverAStrip) {
  // k = (3 D / 4) |e|^2 / (A_a + A_b), D = G h^3 / 3.
  const double modulus = bending_modulus(0.3, 0.5);
  EXPECT_NEAR(modulus, 0.3 * 0.125 / 3.0, 1e-15);
  const RestHinge rest = make_rest_hinge(tent(0.0), modulus);
  EXPECT_NEAR(rest.stiffness, 0.75 * modulus * 1.44 / (2 * 0.5 * 1.2 * 1.0), 1e-14);
  EXPECT_EQ(rest.rest_angle, 0.0);
}

TEST(HingeBending, EveryInteriorEdgeOfAClosedMeshIsOneHinge) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  const auto hinges = mesh_hinges(sphere.faces);
  EXPECT_EQ(static_cast<int>(hinges.size()), 3 * sphere.face_count() / 2);
}

TEST(HingeBending, AUniformlyScaledSphereStoresNoBendingEnergy) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  BalloonModel model = neo_hookean_balloon(sphere, 0.5);
  const Eigen::VectorXd rest = Eigen::Map<const Eigen::VectorXd>(sphere.vertices.data(), sphere.vertices.size());
  const Eigen::VectorXd inflated = 1.7 * rest;
  const double membrane_only = model.elastic_energy(inflated);
  const Eigen::VectorXd membrane_gradient = model.elastic_gradient(inflated);
  model.set_bending(true);
  EXPECT_NEAR(model.elastic_energy(inflated), membrane_only, 1e-12 * membrane_only);
  EXPECT_LT((model.elastic_gradient(inflated) - membrane_gradient).norm(), 1e-10 * membrane_gradient.norm());
}

TEST(HingeBending, AssembledHessianWithHingesMatchesDifferencesOfTheModelGradient) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  BalloonModel model = neo_hookean_balloon(sphere, 2.0);
  model.set_bending(true);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(sphere.vertices.data(), sphere.vertices.size()) * 1.3;
  for (int i = 0; i < x.size(); ++i) x[i] += 0.3 * u(rng);
  const std::vector<bool> fixed(static_cast<size_t>(x.size()), false);
  TriangleAssembly assembly(model.faces(), model.vertex_count(), fixed, model.hinges());
  const double pressure = 0.01;
  model.assemble_hessian(x, pressure, assembly, false);
  Eigen::VectorXd direction(x.size());
  for (int i = 0; i < x.size(); ++i) direction[i] = u(rng);
  auto force = [&](const Eigen::VectorXd& y) -> Eigen::VectorXd { return model.elastic_gradient(y) - pressure * model.volume_gradient(y); };
  const double h = 1e-6;
  const Eigen::VectorXd fd = (force(x + h * direction) - force(x - h * direction)) / (2 * h);
  const Eigen::VectorXd product = assembly.multiply(direction);
  EXPECT_LT((product - fd).norm(), 1e-6 * fd.norm());
}

}  // namespace
}  // namespace balloon::fem
