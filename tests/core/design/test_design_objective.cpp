// The design objective: its surface term grows on its schedule (DesignOptions::surface_growth), by the
// factor after every surface_growth_iterations iterations, up to its cap, and only that term moves; its
// Gauss-Newton operator multiplies like the assembled matrix.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "design/balloon_design.hpp"
#include "design/design_objective.hpp"
#include "fem/balloon_model.hpp"
#include "mesh/icosphere.hpp"

namespace balloon {
namespace {

/// A target (an icosphere stretched 1.5 times along x, 162 vertices), a start (a smaller sphere) and
/// the objective between them.
struct ObjectiveScene {
  TriMesh target = stretched_sphere();
  TriMesh start = make_icosphere(5.0, 2);
  fem::BalloonModel model;
  DesignObjective objective;

  explicit ObjectiveScene(const DesignOptions& options)
      : model(start, options.material,
              std::vector<double>(static_cast<size_t>(start.face_count()), options.thickness_mm)),
        objective(target, start, options, model) {}
  static TriMesh stretched_sphere() {
    TriMesh mesh = make_icosphere(10.0, 2);
    mesh.vertices.col(0) *= 1.5;
    return mesh;
  }
};

TEST(DesignObjective, TheSurfaceWeightGrowsOnItsScheduleUpToItsCap) {
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.surface_growth = 3.0;
  options.surface_growth_iterations = 8;
  options.max_surface_growth = 20.0;
  ObjectiveScene scene(options);
  const TriMesh& target = scene.target;
  DesignObjective& objective = scene.objective;

  // A shape off the target: both terms are non-zero.
  Eigen::VectorXd x(3 * target.vertex_count());
  for (int v = 0; v < target.vertex_count(); ++v)
    x.segment<3>(3 * v) = 1.1 * target.vertices.row(v).transpose() + Eigen::Vector3d(0.1 * std::sin(v), 0.0, 0.0);
  const Eigen::VectorXd rest = x;
  const double surface = objective.surface_term(x, nullptr);
  const double distance = objective.distance().value(x);
  ASSERT_GT(surface, 0.0);
  ASSERT_GT(distance, 0.0);
  EXPECT_DOUBLE_EQ(objective.surface_weight(), 100.0);

  EXPECT_FALSE(objective.grow_surface_weight(7)) << "no growth before the 8th iteration";
  EXPECT_TRUE(objective.grow_surface_weight(8));
  EXPECT_DOUBLE_EQ(objective.surface_weight(), 300.0);
  EXPECT_NEAR(objective.surface_term(x, nullptr), 3.0 * surface, 1e-12 * surface);
  EXPECT_NEAR(objective.value(rest, x), distance + 3.0 * surface, 1e-12 * (distance + surface));
  EXPECT_FALSE(objective.grow_surface_weight(15)) << "the same growth until the 16th";
  EXPECT_TRUE(objective.grow_surface_weight(16));
  EXPECT_DOUBLE_EQ(objective.surface_weight(), 900.0);
  EXPECT_TRUE(objective.grow_surface_weight(24));
  EXPECT_DOUBLE_EQ(objective.surface_weight(), 2000.0) << "capped at 20 times k_surface";
  EXPECT_FALSE(objective.grow_surface_weight(400));
  // A resumed design takes the growth of its checkpoint's iteration, also backwards.
  EXPECT_TRUE(objective.grow_surface_weight(9));
  EXPECT_DOUBLE_EQ(objective.surface_weight(), 300.0);

  // The gradient follows the weight: shape_gradient = grad E_dist + 3 grad E_surf.
  Eigen::VectorXd distance_gradient, surface_gradient;
  objective.distance().gradient(x, distance_gradient);
  DesignObjective unit(target, scene.start, options, scene.model);
  unit.surface_term(x, &surface_gradient);
  EXPECT_LE((objective.shape_gradient(x) - distance_gradient - 3.0 * surface_gradient).norm(),
            1e-12 * (distance_gradient.norm() + surface_gradient.norm()));
}

TEST(DesignObjective, AGrowthBelowOneIsRefused) {
  TriMesh target = make_icosphere(10.0, 2);
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.max_iterations = 1;
  for (const auto& [growth, every, cap] : std::vector<std::tuple<double, int, double>>{
           {0.5, 8, 1000.0}, {3.0, 0, 1000.0}, {3.0, 8, 0.5}, {NAN, 8, 1000.0}, {3.0, 8, INFINITY}}) {
    options.surface_growth = growth;
    options.surface_growth_iterations = every;
    options.max_surface_growth = cap;
    const DesignResult result = design_balloon(target, options);
    EXPECT_EQ(result.stop, DesignStop::StartFailed);
    EXPECT_NE(result.message.find("surface term's growth"), std::string::npos) << result.message;
  }
}

/// A shape near the target (bumped, turned and moved: off its Procrustes placement) and two directions.
struct ShapeNearTarget {
  Eigen::VectorXd x, v, u;
  explicit ShapeNearTarget(const TriMesh& target) {
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
    x.resize(3 * target.vertex_count());
    v.resizeLike(x);
    u.resizeLike(x);
    for (int i = 0; i < target.vertex_count(); ++i) {
      const Eigen::Vector3d p = 1.05 * target.vertices.row(i).transpose() +
                                Eigen::Vector3d(0.3 * std::sin(i), 0.2 * std::cos(3 * i), 0.0);
      x.segment<3>(3 * i) = turn * p + Eigen::Vector3d(2.0, -1.0, 0.5);
      v.segment<3>(3 * i) = Eigen::Vector3d(std::cos(i), std::sin(2 * i), 0.5);
      u.segment<3>(3 * i) = Eigen::Vector3d(std::sin(5 * i), 0.3, std::cos(i));
    }
  }
  /// A translation and an infinitesimal rotation of x.
  std::vector<Eigen::VectorXd> rigid_motions() const {
    Eigen::VectorXd translation(x.size()), rotation(x.size());
    for (Eigen::Index i = 0; i < x.size() / 3; ++i) {
      translation.segment<3>(3 * i) = Eigen::Vector3d(0.5, -1.0, 2.0);
      rotation.segment<3>(3 * i) = Eigen::Vector3d(0.3, 1.0, -0.4).cross(Eigen::Vector3d(x.segment<3>(3 * i)));
    }
    return {translation, rotation};
  }
};

TEST(DesignObjective, ItsSurfaceTermIsRigidInvariantWithAGradientThatMatchesCentralDifferences) {
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  ObjectiveScene scene(options);
  const ShapeNearTarget shape(scene.target);
  Eigen::VectorXd gradient;
  const double value = scene.objective.surface_term(shape.x, &gradient);
  ASSERT_GT(value, 0.0);
  // Moved rigidly, the shape keeps its placement on the target, so the term keeps its value.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0, 1, 2).normalized()).toRotationMatrix();
  Eigen::VectorXd moved = shape.x;
  for (Eigen::Index i = 0; i < moved.size() / 3; ++i)
    moved.segment<3>(3 * i) = turn * Eigen::Vector3d(shape.x.segment<3>(3 * i)) + Eigen::Vector3d(-4.0, 1.0, 3.0);
  EXPECT_NEAR(scene.objective.surface_term(moved, nullptr), value, 1e-10 * value);
  for (const Eigen::VectorXd& direction : {shape.v, shape.u}) {
    const double h = 1e-6;
    const double difference = (scene.objective.surface_term(shape.x + h * direction, nullptr) -
                               scene.objective.surface_term(shape.x - h * direction, nullptr)) / (2.0 * h);
    EXPECT_NEAR(gradient.dot(direction), difference, 1e-5 * gradient.norm() * direction.norm());
  }
}

TEST(DesignObjective, ItsGaussNewtonOperatorIsSymmetricBlindToRigidMotionsAndAddsThePlacedSurfaceTerm) {
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  ObjectiveScene scene(options);
  DesignObjective& objective = scene.objective;
  objective.grow_surface_weight(8);  // a weight other than the start's, so both terms count
  const ShapeNearTarget shape(scene.target);
  const ObjectiveGaussNewton hessian = objective.gauss_newton(shape.x);

  // Without the surface term it is E_dist's assembled Gauss-Newton matrix.
  DesignOptions distance_only = options;
  distance_only.k_surface = 0.0;
  DesignObjective distance(scene.target, scene.start, distance_only, scene.model);
  std::vector<Eigen::Triplet<double>> entries;
  objective.distance().hessian_triplets(shape.x, entries, DistanceHessian::GaussNewton);
  Eigen::SparseMatrix<double> assembled(shape.x.size(), shape.x.size());
  assembled.setFromTriplets(entries.begin(), entries.end());
  const Eigen::VectorXd distance_part = assembled * shape.v;
  ASSERT_GT(distance_part.norm(), 0.0);
  EXPECT_LE((distance.gauss_newton(shape.x)(shape.v) - distance_part).norm(), 1e-12 * distance_part.norm());

  // The surface part: symmetric, positive semi-definite, and nothing for a rigid motion.
  const Eigen::VectorXd hv = hessian(shape.v), hu = hessian(shape.u);
  EXPECT_NEAR(shape.u.dot(hv), shape.v.dot(hu), 1e-10 * hv.norm() * shape.u.norm());
  EXPECT_GT(shape.v.dot(hv - distance_part), 0.0);
  for (const Eigen::VectorXd& rigid : shape.rigid_motions())
    EXPECT_LE(hessian(rigid).norm(), 1e-9 * hv.norm() * rigid.norm() / shape.v.norm());
}

}  // namespace
}  // namespace balloon
