#include "design/self_collision.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>

#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

/// A sphere squashed along z until its top and bottom sheets are `gap` mm apart at the poles.
Eigen::VectorXd squashed(const TriMesh& sphere, double radius, double gap) {
  Positions p = sphere.vertices;
  p.col(2) *= 0.5 * gap / radius;
  return flat(p);
}

TEST(SelfCollision, NothingOnAPlainSphere) {
  const TriMesh sphere = design_test::make_icosphere(4, 50.0);  // 2562 vertices
  SelfCollision collision(sphere);
  // Defaults: eps_c = mean edge length, eps_gd = 3 eps_c.
  EXPECT_GT(collision.contact_distance_mm(), 2.0);
  EXPECT_LT(collision.contact_distance_mm(), 4.5);
  EXPECT_NEAR(collision.geodesic_exclusion_mm(), 3.0 * collision.contact_distance_mm(), 1e-12);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(collision.update(flat(sphere.vertices)), 0);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("update on 2562 vertices: %.2f ms\n", ms);
  EXPECT_FALSE(collision.any_active());
  EXPECT_EQ(collision.value(flat(sphere.vertices)), 0.0);
  Eigen::VectorXd g;
  collision.gradient(flat(sphere.vertices), g);
  EXPECT_EQ(g.size(), 3 * sphere.vertex_count());
  EXPECT_EQ(g.norm(), 0.0);
  // Neighbours are excluded, far vertices are not.
  EXPECT_TRUE(collision.excluded(sphere.faces(0, 0), sphere.faces(0, 1)));
  int south = 0, north = 0;
  sphere.vertices.col(2).minCoeff(&south);
  sphere.vertices.col(2).maxCoeff(&north);
  EXPECT_FALSE(collision.excluded(south, north));
}

TEST(SelfCollision, SquashedSphereTouchesItself) {
  const double radius = 20.0;
  const TriMesh sphere = design_test::make_icosphere(2, radius);  // 162 vertices, edge ~ 4.4 mm
  SelfCollisionOptions options;
  options.contact_distance_mm = 1.0;
  options.geodesic_exclusion_mm = 4.0;
  options.stiffness = 2.0;
  SelfCollision collision(sphere, options);
  const Eigen::VectorXd x = squashed(sphere, radius, 0.6);
  const int pairs = collision.update(x);
  EXPECT_GT(pairs, 0);
  EXPECT_TRUE(collision.any_active());
  // Every pair is closer than eps_c and joins the two sheets (z of opposite signs before squashing).
  for (const auto& [i, j] : collision.active_pairs()) {
    EXPECT_LT(i, j);
    EXPECT_LT((x.segment<3>(3 * i) - x.segment<3>(3 * j)).norm(), 1.0);
    EXPECT_LT(sphere.vertices(i, 2) * sphere.vertices(j, 2), 0.0);
  }
  // Penalty >= 0 and equal to the sum over pairs of k (eps - d)^3.
  double expected = 0.0;
  for (const auto& [i, j] : collision.active_pairs()) {
    expected += 2.0 * std::pow(1.0 - (x.segment<3>(3 * i) - x.segment<3>(3 * j)).norm(), 3);
  }
  EXPECT_GT(expected, 0.0);
  EXPECT_NEAR(collision.value(x), expected, 1e-12 * expected);

  // Gradient against central differences of the value, Hessian against those of the gradient.
  Eigen::VectorXd g;
  collision.gradient(x, g);
  ASSERT_GT(g.norm(), 1e-6);
  const double h = 1e-6;
  Eigen::VectorXd xp = x, g_fd(x.size()), gp, gm;
  std::vector<Eigen::Triplet<double>> triplets;
  collision.hessian_triplets(x, triplets);
  Eigen::SparseMatrix<double> hess(x.size(), x.size());
  hess.setFromTriplets(triplets.begin(), triplets.end());
  double hess_err2 = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    xp(i) = x(i) + h;
    const double ep = collision.value(xp);
    collision.gradient(xp, gp);
    xp(i) = x(i) - h;
    const double em = collision.value(xp);
    collision.gradient(xp, gm);
    xp(i) = x(i);
    g_fd(i) = (ep - em) / (2 * h);
    hess_err2 += (Eigen::VectorXd(hess.col(i)) - (gp - gm) / (2 * h)).squaredNorm();
  }
  EXPECT_LE((g - g_fd).norm(), 1e-6 * g.norm());
  ASSERT_GT(hess.norm(), 1e-6);
  EXPECT_LE(std::sqrt(hess_err2), 1e-6 * hess.norm());

  // The projected Hessian is PSD (dense eigenvalues over the coordinates of the paired vertices).
  triplets.clear();
  collision.hessian_triplets(x, triplets, true);
  std::vector<int> dofs;
  for (const auto& [i, j] : collision.active_pairs()) {
    for (int c = 0; c < 3; ++c) dofs.push_back(3 * i + c), dofs.push_back(3 * j + c);
  }
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  Eigen::MatrixXd projected = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dofs.size()), static_cast<Eigen::Index>(dofs.size()));
  auto local = [&](int dof) { return std::lower_bound(dofs.begin(), dofs.end(), dof) - dofs.begin(); };
  for (const auto& t : triplets) projected(local(t.row()), local(t.col())) += t.value();
  ASSERT_GT(projected.norm(), 1e-6);
  const double min_eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(projected).eigenvalues().minCoeff();
  EXPECT_GE(min_eig, -1e-10 * projected.norm());

  // Lift the upper sheet 5 mm: every pair is now farther than eps_c and the stale list gives 0 (C2
  // cut-off at eps_c, no jump).
  Eigen::VectorXd apart = x;
  for (int v = 0; v < sphere.vertex_count(); ++v) {
    if (sphere.vertices(v, 2) > 0.0) apart(3 * v + 2) += 5.0;
  }
  EXPECT_EQ(collision.value(apart), 0.0);
}

TEST(SelfCollision, GeodesicNeighboursAreNeverPairs) {
  const TriMesh sphere = design_test::make_icosphere(3, 20.0);
  SelfCollisionOptions options;
  options.contact_distance_mm = 100.0;  // everything is "close"...
  options.geodesic_exclusion_mm = 10.0;
  SelfCollision collision(sphere, options);
  collision.update(flat(sphere.vertices));
  // ...but pairs within 10 mm of edge-graph distance (>= Euclidean distance) are excluded.
  for (const auto& [i, j] : collision.active_pairs()) {
    EXPECT_GT((sphere.vertices.row(i) - sphere.vertices.row(j)).norm(), 10.0 / 1.2);
  }
  const long long all_pairs = 642LL * 641 / 2;
  EXPECT_LT(static_cast<long long>(collision.active_pairs().size()), all_pairs);
  EXPECT_EQ(static_cast<long long>(collision.active_pairs().size()) + collision.excluded_pair_count() / 2, all_pairs);
}

}  // namespace
}  // namespace balloon
