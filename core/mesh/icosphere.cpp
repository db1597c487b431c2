#include "mesh/icosphere.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace balloon {

namespace {

constexpr int MAX_SUBDIVISIONS = 7;  // 163,842 vertices; beyond that nobody wants a test sphere

}  // namespace

TriMesh make_icosphere(double radius_mm, int subdivisions) {
  if (subdivisions < 0 || subdivisions > MAX_SUBDIVISIONS) {
    throw std::invalid_argument("make_icosphere: subdivisions must be in 0.." +
                                std::to_string(MAX_SUBDIVISIONS) + ", got " +
                                std::to_string(subdivisions));
  }
  if (!std::isfinite(radius_mm) || radius_mm <= 0.0) {
    throw std::invalid_argument("make_icosphere: radius must be finite and positive, got " +
                                std::to_string(radius_mm));
  }

  // The 12 vertices (0, +-1, +-phi) and cyclic permutations, and 20 faces wound outwards.
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::RowVector3d> points = {
      {-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
      {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  std::vector<Eigen::Vector3i> triangles = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : points) p.normalize();

  for (int level = 0; level < subdivisions; ++level) {
    // Each edge gets one midpoint, shared by its two faces; keyed by the sorted vertex pair.
    std::unordered_map<std::uint64_t, int> midpoints;
    midpoints.reserve(triangles.size() * 3 / 2);
    auto midpoint = [&](int a, int b) {
      const auto key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                       static_cast<std::uint64_t>(std::max(a, b));
      const auto [it, inserted] = midpoints.try_emplace(key, static_cast<int>(points.size()));
      if (inserted) points.push_back((points[a] + points[b]).normalized());
      return it->second;
    };
    std::vector<Eigen::Vector3i> finer;
    finer.reserve(triangles.size() * 4);
    for (const auto& t : triangles) {
      const int ab = midpoint(t[0], t[1]);
      const int bc = midpoint(t[1], t[2]);
      const int ca = midpoint(t[2], t[0]);
      finer.emplace_back(t[0], ab, ca);
      finer.emplace_back(t[1], bc, ab);
      finer.emplace_back(t[2], ca, bc);
      finer.emplace_back(ab, bc, ca);
    }
    triangles = std::move(finer);
  }

  TriMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    mesh.vertices.row(static_cast<Eigen::Index>(i)) = radius_mm * points[i];
  }
  mesh.faces.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    mesh.faces.row(static_cast<Eigen::Index>(f)) = triangles[f].transpose();
  }
  return mesh;
}

}  // namespace balloon
