#include "mesh/polygon_triangulation.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace balloon {
namespace {

double cross_2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Whether `p` lies inside or on the counter-clockwise triangle (a, b, c), within `tolerance` (an area).
bool inside_or_on(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  double tolerance) {
  return cross_2d(b - a, p - a) >= -tolerance && cross_2d(c - b, p - b) >= -tolerance &&
         cross_2d(a - c, p - c) >= -tolerance;
}

}  // namespace

std::string polygon_corner_problem(long corners) {
  if (corners >= 3 && corners <= MAX_POLYGON_CORNERS) return "";
  if (corners < 3) return "has " + std::to_string(corners) + " vertices; a face needs at least 3";
  return "has " + std::to_string(corners) + " vertices; polygons of up to " + std::to_string(MAX_POLYGON_CORNERS) +
         " are split into triangles";
}

std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Eigen::Vector3d>& corners) {
  const int n = static_cast<int>(corners.size());
  std::vector<std::array<int, 3>> triangles;
  if (n < 3) return triangles;
  triangles.reserve(static_cast<std::size_t>(n - 2));
  // Newell's normal: the polygon's area vector, along which its winding turns counter-clockwise.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double size = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = corners[static_cast<std::size_t>(i)];
    const Eigen::Vector3d& q = corners[static_cast<std::size_t>((i + 1) % n)];
    normal += p.cross(q);
    size = std::max(size, (q - p).norm());
  }
  std::vector<int> remaining(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) remaining[static_cast<std::size_t>(i)] = i;
  const double area_scale = size * size;
  if (normal.norm() > 1e-12 * area_scale) {
    // In-plane coordinates (u, v) with u x v along the normal: the polygon runs counter-clockwise in them.
    const Eigen::Vector3d w = normal.normalized();
    const Eigen::Vector3d u = w.unitOrthogonal();
    const Eigen::Vector3d v = w.cross(u);
    std::vector<Eigen::Vector2d> flat(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d& p = corners[static_cast<std::size_t>(i)];
      flat[static_cast<std::size_t>(i)] = Eigen::Vector2d(p.dot(u), p.dot(v));
    }
    const double tolerance = 1e-12 * area_scale;
    long tests_left = 8L * n * n;
    while (remaining.size() > 3 && tests_left > 0) {
      const std::size_t m = remaining.size();
      bool clipped = false;
      for (std::size_t k = 0; k < m && !clipped; ++k) {
        const int a = remaining[(k + m - 1) % m], b = remaining[k], c = remaining[(k + 1) % m];
        const Eigen::Vector2d &pa = flat[static_cast<std::size_t>(a)], &pb = flat[static_cast<std::size_t>(b)],
                              &pc = flat[static_cast<std::size_t>(c)];
        if (!(cross_2d(pb - pa, pc - pb) > tolerance)) continue;  // reflex or flat: no ear
        bool empty = true;
        for (const int other : remaining) {
          if (other == a || other == b || other == c) continue;
          --tests_left;
          if (inside_or_on(flat[static_cast<std::size_t>(other)], pa, pb, pc, tolerance)) {
            empty = false;
            break;
          }
        }
        if (!empty) continue;
        triangles.push_back({a, b, c});
        remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(k));
        clipped = true;
      }
      if (!clipped) break;
    }
  }
  // A triangle left, or no ear found (no area, or the polygon crosses itself): a fan over what is left.
  for (std::size_t k = 1; k + 1 < remaining.size(); ++k) triangles.push_back({remaining[0], remaining[k], remaining[k + 1]});
  return triangles;
}

void append_polygon_triangles(const std::vector<int>& face, const std::vector<double>& coordinates,
                              std::vector<int>& triangle_indices) {
  if (face.size() == 3) {
    triangle_indices.insert(triangle_indices.end(), face.begin(), face.end());
    return;
  }
  std::vector<Eigen::Vector3d> corners;
  corners.reserve(face.size());
  for (const int v : face) {
    const std::size_t at = 3 * static_cast<std::size_t>(v);
    corners.emplace_back(coordinates[at], coordinates[at + 1], coordinates[at + 2]);
  }
  for (const std::array<int, 3>& triangle : triangulate_polygon(corners))
    for (const int k : triangle) triangle_indices.push_back(face[static_cast<std::size_t>(k)]);
}

}  // namespace balloon
