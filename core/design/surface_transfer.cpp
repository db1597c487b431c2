#include "design/surface_transfer.hpp"

#include <Eigen/Dense>
#include <stdexcept>

#include "design/surface_distance.hpp"

namespace balloon {

namespace {

/// Barycentric coordinates of p (on or near the triangle a, b, c) in that triangle, clamped to it.
Eigen::Vector3d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, d = p - a;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 0.0)) return Eigen::Vector3d(1.0, 0.0, 0.0);  // degenerate: the first corner's value
  const double u = (g22 * e1.dot(d) - g12 * e2.dot(d)) / det;
  const double v = (g11 * e2.dot(d) - g12 * e1.dot(d)) / det;
  Eigen::Vector3d weights(1.0 - u - v, u, v);
  weights = weights.cwiseMax(0.0);
  return weights / weights.sum();
}

}  // namespace

Positions transfer_vertex_field(const TriMesh& surface, const Positions& field, const Positions& points) {
  if (field.rows() != surface.vertex_count() || field.cols() != 3)
    throw std::invalid_argument("transfer_vertex_field: one field row per surface vertex is needed");
  const SurfaceDistance closest_surface(surface);
  Positions closest;
  Eigen::VectorXi faces;
  closest_surface.closest_points(points, closest, nullptr, &faces);
  Positions values(points.rows(), 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3i corners = surface.faces.row(faces(i)).transpose();
    const Eigen::Vector3d weights =
        barycentric(closest.row(i).transpose(), surface.vertices.row(corners[0]).transpose(),
                    surface.vertices.row(corners[1]).transpose(), surface.vertices.row(corners[2]).transpose());
    values.row(i) = weights[0] * field.row(corners[0]) + weights[1] * field.row(corners[1]) +
                    weights[2] * field.row(corners[2]);
  }
  return values;
}

}  // namespace balloon
