// The rigid support of a free-floating balloon: steps without their rigid part, a drifted shape put back
// on its support, and a volume-controlled solve that floats on it reaching the pinned solve's equilibrium.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "ellipsoid_fixture.hpp"
#include "fem/balloon_model.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/equilibrium_solver.hpp"
#include "solve/rigid_modes.hpp"

namespace balloon {
namespace {

/// The fixture's ellipsoid as a flat vector.
Eigen::VectorXd ellipsoid(TriMesh& mesh) {
  mesh = test::ellipsoid();
  return flat(mesh.vertices);
}

Eigen::VectorXd rigidly_moved(const Eigen::VectorXd& x, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& shift) {
  Eigen::VectorXd y = x;
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) y.segment<3>(3 * v) = rotation * x.segment<3>(3 * v) + shift;
  return y;
}

TEST(RigidSupport, AStepLosesItsRigidPartAndKeepsItsDeformation) {
  TriMesh mesh;
  const Eigen::VectorXd x = ellipsoid(mesh);
  // A deformation with no rigid part (an even stretch along x about the centroid at the origin)...
  Eigen::VectorXd deformation = Eigen::VectorXd::Zero(x.size());
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) deformation[3 * v] = 0.1 * x[3 * v] * std::abs(x[3 * v + 1]);
  const Eigen::VectorXd pure = without_rigid_motion(x, deformation);
  // ...plus an infinitesimal rotation and translation.
  Eigen::VectorXd rigid(x.size());
  const Eigen::Vector3d omega(0.02, -0.03, 0.01), shift(0.5, -0.2, 0.3);
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) rigid.segment<3>(3 * v) = shift + omega.cross(Eigen::Vector3d(x.segment<3>(3 * v)));
  EXPECT_LT(without_rigid_motion(x, rigid).norm(), 1e-12 * rigid.norm());
  EXPECT_LT((without_rigid_motion(x, pure + rigid) - pure).norm(), 1e-12 * rigid.norm());
  EXPECT_GT(pure.norm(), 0.5 * deformation.norm());
}

TEST(RigidSupport, ADriftedShapeReturnsToItsSupport) {
  TriMesh mesh;
  const Eigen::VectorXd held = ellipsoid(mesh);
  const std::vector<int> support = rigid_support_coordinates(mesh.vertices);
  ASSERT_EQ(support.size(), 6u);
  // Eight degrees about a skew axis and 3 mm away: far beyond one linearised correction.
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(8.0 * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd x = rigidly_moved(held, rotation, Eigen::Vector3d(3.0, -1.0, 2.0));
  restore_rigid_support(x, held, support);
  EXPECT_LT((x - held).cwiseAbs().maxCoeff(), 1e-9);  // mm: the whole shape, not only the support
}

TEST(RigidSupport, AVolumeSolveFloatingOnItReachesThePinnedEquilibrium) {
  TriMesh mesh;
  const Eigen::VectorXd rest = ellipsoid(mesh);
  const Material silicone = test::silicone();
  const double target_volume = 3.0 * enclosed_volume(mesh.vertices, mesh.faces);
  std::vector<bool> support(static_cast<size_t>(rest.size()), false);
  for (int c : rigid_support_coordinates(mesh.vertices)) support[static_cast<size_t>(c)] = true;
  NewtonSettings settings;
  settings.relative_tolerance = 1e-9;
  settings.max_iterations = 200;

  Eigen::VectorXd solutions[2];
  for (int floating = 0; floating < 2; ++floating) {
    fem::BalloonModel model(mesh, silicone, std::vector<double>(static_cast<size_t>(mesh.face_count()), 0.5));
    EquilibriumSolver solver(model, support);
    solver.set_support_is_rigid(floating == 1);
    Eigen::VectorXd x = rest * std::cbrt(3.0);
    const Eigen::VectorXd entry = x;
    double pressure = 0.0;
    const NewtonReport report = solver.solve_volume(x, pressure, target_volume, settings);
    ASSERT_TRUE(report.converged) << report.message;
    for (size_t c = 0; c < support.size(); ++c) {
      if (support[c]) {
        EXPECT_NEAR(x[static_cast<Eigen::Index>(c)], entry[static_cast<Eigen::Index>(c)], 1e-9);
      }
    }
    EXPECT_LE(report.residual_norm, settings.relative_tolerance * solver.force_scale(x, pressure));
    solutions[floating] = x;
  }
  // One equilibrium held in one place: the same shape to well below the mesh's scale (20 mm).
  EXPECT_LT((solutions[1] - solutions[0]).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace balloon
