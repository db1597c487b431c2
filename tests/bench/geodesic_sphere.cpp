#include "geodesic_sphere.hpp"

#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "mesh/icosphere.hpp"

namespace balloon::bench {

balloon::TriMesh geodesic_sphere(double radius_mm, int n) {
  const balloon::TriMesh ico = balloon::make_icosphere(1.0, 0);
  std::vector<Eigen::Vector3d> points;
  // Points on shared icosahedron edges are made twice: merged by their position rounded to 1e-6 mm.
  std::map<std::tuple<long long, long long, long long>, int> index;
  auto vertex = [&](Eigen::Vector3d p) {
    p = p.normalized() * radius_mm;
    const auto key = std::make_tuple(std::llround(p.x() * 1e6), std::llround(p.y() * 1e6), std::llround(p.z() * 1e6));
    const auto [it, added] = index.emplace(key, static_cast<int>(points.size()));
    if (added) points.push_back(p);
    return it->second;
  };
  std::vector<Eigen::Vector3i> faces;
  for (int f = 0; f < ico.face_count(); ++f) {
    const Eigen::Vector3d a = ico.vertices.row(ico.faces(f, 0)).transpose();
    const Eigen::Vector3d b = ico.vertices.row(ico.faces(f, 1)).transpose();
    const Eigen::Vector3d c = ico.vertices.row(ico.faces(f, 2)).transpose();
    std::vector<std::vector<int>> id(static_cast<size_t>(n) + 1);
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n - i; ++j) id[static_cast<size_t>(i)].push_back(vertex(a + (b - a) * i / n + (c - a) * j / n));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n - i; ++j) {
        const auto& row = id[static_cast<size_t>(i)];
        const auto& next = id[static_cast<size_t>(i) + 1];
        faces.emplace_back(row[static_cast<size_t>(j)], next[static_cast<size_t>(j)], row[static_cast<size_t>(j) + 1]);
        if (i + j + 1 < n)
          faces.emplace_back(next[static_cast<size_t>(j)], next[static_cast<size_t>(j) + 1], row[static_cast<size_t>(j) + 1]);
      }
  }
  balloon::TriMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t v = 0; v < points.size(); ++v) mesh.vertices.row(static_cast<Eigen::Index>(v)) = points[v].transpose();
  mesh.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) mesh.faces.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return mesh;
}

}  // namespace balloon::bench
