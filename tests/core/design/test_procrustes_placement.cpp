// The Procrustes placement's linearization: push_forward against central differences of the placement,
// pull_back its exact adjoint, and a function of the placed points blind to rigid motions of the points.
#include <gtest/gtest.h>

#include <cmath>

#include "design/procrustes_placement.hpp"
#include "mesh/icosphere.hpp"

namespace balloon {
namespace {

/// An icosphere stretched along x (the reference) and a copy deformed, turned and moved (the points).
struct PlacementScene {
  Positions reference;
  Positions points;
  PlacementScene() {
    reference = make_icosphere(10.0, 2).vertices;
    reference.col(0) *= 1.5;
    const Eigen::Matrix3d turn =
        (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
    points = reference;
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const Eigen::Vector3d p = points.row(i).transpose();
      const Eigen::Vector3d bumped = 1.1 * p + Eigen::Vector3d(0.4 * std::sin(i), 0.3 * std::cos(2.0 * i), 0.2);
      points.row(i) = (turn * bumped + Eigen::Vector3d(5.0, -3.0, 2.0)).transpose();
    }
  }
  Eigen::VectorXd direction(double phase) const {
    Eigen::VectorXd v(points.size());
    for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = std::sin(0.37 * i + phase) + 0.3;
    return v;
  }
  Positions moved(const Eigen::VectorXd& v, double h) const {
    Positions out = points;
    out += h * Eigen::Map<const Positions>(v.data(), points.rows(), 3);
    return out;
  }
};

Eigen::VectorXd flat_copy(const Positions& p) { return Eigen::Map<const Eigen::VectorXd>(p.data(), p.size()); }

TEST(ProcrustesPlacement, PushForwardIsTheCentralDifferenceOfThePlacement) {
  const PlacementScene scene;
  const ProcrustesPlacement placement(scene.points, scene.reference);
  for (double phase : {0.0, 1.3, 2.9}) {
    const Eigen::VectorXd v = scene.direction(phase);
    const double h = 1e-5;
    const Eigen::VectorXd difference =
        (flat_copy(ProcrustesPlacement(scene.moved(v, h), scene.reference).placed()) -
         flat_copy(ProcrustesPlacement(scene.moved(v, -h), scene.reference).placed())) / (2.0 * h);
    const Eigen::VectorXd linear = placement.push_forward(v);
    ASSERT_GT(difference.norm(), 0.0);
    EXPECT_LE((linear - difference).norm(), 1e-7 * difference.norm()) << "phase " << phase;
  }
}

TEST(ProcrustesPlacement, PullBackIsTheAdjointOfPushForward) {
  const PlacementScene scene;
  const ProcrustesPlacement placement(scene.points, scene.reference);
  const Eigen::VectorXd v = scene.direction(0.5), g = scene.direction(2.0);
  const double forward = g.dot(placement.push_forward(v));
  const double backward = placement.pull_back(g).dot(v);
  EXPECT_NEAR(forward, backward, 1e-12 * std::abs(forward));
}

TEST(ProcrustesPlacement, AGradientPulledBackIgnoresRigidMotionsOfThePoints) {
  const PlacementScene scene;
  const ProcrustesPlacement placement(scene.points, scene.reference);
  const Eigen::VectorXd pulled = placement.pull_back(scene.direction(1.0));
  Eigen::VectorXd translation(scene.points.size()), rotation(scene.points.size());
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -1.0, 0.5).normalized();
  for (Eigen::Index i = 0; i < scene.points.rows(); ++i) {
    translation.segment<3>(3 * i) = Eigen::Vector3d(1.0, 2.0, -0.5);
    rotation.segment<3>(3 * i) = axis.cross(Eigen::Vector3d(scene.points.row(i).transpose()));
  }
  EXPECT_LE(std::abs(pulled.dot(translation)), 1e-12 * pulled.norm() * translation.norm());
  EXPECT_LE(std::abs(pulled.dot(rotation)), 1e-12 * pulled.norm() * rotation.norm());
}

}  // namespace
}  // namespace balloon
