#include "mesh/polygon_triangulation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace balloon {
namespace {

/// Sum of the triangles' area vectors (each a half cross product, in the given winding).
Eigen::Vector3d area_vector(const std::vector<Eigen::Vector3d>& corners, const std::vector<std::array<int, 3>>& triangles) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& t : triangles) {
    const Eigen::Vector3d& a = corners[static_cast<std::size_t>(t[0])];
    sum += 0.5 * (corners[static_cast<std::size_t>(t[1])] - a).cross(corners[static_cast<std::size_t>(t[2])] - a);
  }
  return sum;
}

TEST(PolygonTriangulation, AConcaveFaceSplitsInsideItselfInItsOwnWinding) {
  // An L of area 3 (three unit squares), counter-clockwise about +z, tilted out of every axis plane. A fan
  // from corner 0 would cover the notch: a triangle outside the face.
  const std::vector<Eigen::Vector2d> l_shape = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  for (int start = 0; start < 6; ++start) {  // every corner first, the reflex one (3) included
    std::vector<Eigen::Vector3d> corners;
    for (int i = 0; i < 6; ++i) {
      const Eigen::Vector2d& p = l_shape[static_cast<std::size_t>((start + i) % 6)];
      corners.push_back(tilt * Eigen::Vector3d(p.x(), p.y(), 0.0));
    }
    const auto triangles = triangulate_polygon(corners);
    ASSERT_EQ(triangles.size(), 4u);
    const Eigen::Vector3d normal = tilt * Eigen::Vector3d::UnitZ();
    double total = 0.0;
    for (const auto& t : triangles) {
      const Eigen::Vector3d& a = corners[static_cast<std::size_t>(t[0])];
      const double area =
          0.5 * (corners[static_cast<std::size_t>(t[1])] - a).cross(corners[static_cast<std::size_t>(t[2])] - a).dot(normal);
      EXPECT_GT(area, 0.0) << "every triangle turns the face's way (start " << start << ")";
      total += area;
    }
    EXPECT_NEAR(total, 3.0, 1e-12) << "the triangles tile the L exactly (start " << start << ")";
  }
}

TEST(PolygonTriangulation, AWarpedQuadAndADegenerateFaceStillGiveCornersMinusTwoTriangles) {
  // A quad bent 0.1 out of its plane splits into 2 triangles whose area vector stays along its normal.
  const std::vector<Eigen::Vector3d> warped = {{0, 0, 0}, {1, 0, 0.1}, {1, 1, 0}, {0, 1, 0.1}};
  const auto halves = triangulate_polygon(warped);
  ASSERT_EQ(halves.size(), 2u);
  EXPECT_GT(area_vector(warped, halves).z(), 0.9);
  // All corners on a line: no area and no ear; fanned, still one triangle per corner beyond two.
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}};
  EXPECT_EQ(triangulate_polygon(line).size(), 3u);
}

}  // namespace
}  // namespace balloon
