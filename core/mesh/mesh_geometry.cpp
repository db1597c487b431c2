#include "mesh/mesh_geometry.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace balloon {

double enclosed_volume(const Positions& vertices, const Faces& faces) {
  if (vertices.rows() == 0) return 0.0;
  // Tetrahedra on a vertex of the mesh instead of the origin: the same volume for a closed surface, with
  // products of the mesh's size rather than of its distance from the origin (mesh/centred_frame.hpp).
  const Eigen::RowVector3d o = vertices.row(0);
  double six_volume = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::RowVector3d a = vertices.row(faces(f, 0)) - o;
    const Eigen::RowVector3d b = vertices.row(faces(f, 1)) - o;
    const Eigen::RowVector3d c = vertices.row(faces(f, 2)) - o;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

double triangle_area(const Positions& vertices, const Eigen::Vector3i& face) {
  const Eigen::RowVector3d a = vertices.row(face[0]), b = vertices.row(face[1]), c = vertices.row(face[2]);
  return 0.5 * (b - a).cross(c - a).norm();
}

double surface_area(const Positions& vertices, const Faces& faces) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) area += triangle_area(vertices, faces.row(f).transpose());
  return area;
}

double bounding_box_diagonal(const Positions& vertices) {
  if (vertices.rows() == 0) return 0.0;
  return (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
}

double scale_to_diagonal(Positions& vertices, double diagonal_mm) {
  const double factor = diagonal_mm / bounding_box_diagonal(vertices);
  if (!std::isfinite(factor) || !(factor > 0.0)) return 0.0;
  vertices *= factor;
  return factor;
}

Eigen::RowVector3d centroid(const Positions& vertices) {
  if (vertices.rows() == 0) return Eigen::RowVector3d::Zero();
  return vertices.colwise().mean();
}

std::array<double, 3> corner_angles_deg(const Positions& vertices, const Eigen::Vector3i& face) {
  std::array<double, 3> angles{};
  for (int k = 0; k < 3; ++k) {
    const Eigen::RowVector3d corner = vertices.row(face[k]);
    const Eigen::RowVector3d u = vertices.row(face[(k + 1) % 3]) - corner;
    const Eigen::RowVector3d w = vertices.row(face[(k + 2) % 3]) - corner;
    // atan2 of |u x w| and u . w stays accurate for the tiny angles of slivers, where acos does not.
    angles[static_cast<size_t>(k)] = std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / std::numbers::pi;
  }
  return angles;
}

double min_angle_deg(const Positions& vertices, const Faces& faces) {
  // A triangle's smallest angle is the one opposite its shortest edge (law of sines): one atan2 per
  // face instead of three (every upload's validation runs this; at 2,500 vertices it was a third of it).
  double min_angle = 180.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const std::array<Eigen::RowVector3d, 3> corner{vertices.row(faces(f, 0)), vertices.row(faces(f, 1)),
                                                   vertices.row(faces(f, 2))};
    // The squared length of the edge opposite each corner.
    std::array<double, 3> opposite{};
    for (std::size_t k = 0; k < 3; ++k) opposite[k] = (corner[(k + 2) % 3] - corner[(k + 1) % 3]).squaredNorm();
    const auto k = static_cast<std::size_t>(std::min_element(opposite.begin(), opposite.end()) - opposite.begin());
    const Eigen::RowVector3d u = corner[(k + 1) % 3] - corner[k];
    const Eigen::RowVector3d w = corner[(k + 2) % 3] - corner[k];
    min_angle = std::min(min_angle, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / std::numbers::pi);
  }
  return min_angle;
}

EdgeTopology build_edge_topology(const Faces& faces, int vertex_count) {
  const Eigen::Index face_count = faces.rows();
  // One record per half-edge; sorting groups the (at most two) half-edges of each undirected edge.
  struct HalfEdge {
    std::uint64_t key;
    int face;
    int corner;  // the half-edge runs from faces(face, corner+1) to faces(face, corner+2)
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(static_cast<std::size_t>(3 * face_count));
  for (Eigen::Index f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces(f, (k + 1) % 3);
      const int b = faces(f, (k + 2) % 3);
      if (a < 0 || a >= vertex_count || b < 0 || b >= vertex_count) {
        throw std::invalid_argument("build_edge_topology: face " + std::to_string(f) +
                                    " has a vertex index out of range");
      }
      const auto lo = static_cast<std::uint64_t>(std::min(a, b));
      const auto hi = static_cast<std::uint64_t>(std::max(a, b));
      half_edges.push_back({(lo << 32) | hi, static_cast<int>(f), k});
    }
  }
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key ? x.key < y.key : (x.face != y.face ? x.face < y.face : x.corner < y.corner);
  });

  std::vector<std::size_t> group_starts;
  for (std::size_t i = 0; i < half_edges.size(); ++i) {
    if (i == 0 || half_edges[i].key != half_edges[i - 1].key) group_starts.push_back(i);
  }
  const auto edge_count = static_cast<Eigen::Index>(group_starts.size());
  EdgeTopology topology;
  topology.edges.resize(edge_count, 2);
  topology.edge_faces.setConstant(edge_count, 2, -1);
  topology.edge_opposite.setConstant(edge_count, 2, -1);
  topology.face_edges.resize(face_count, 3);
  for (Eigen::Index e = 0; e < edge_count; ++e) {
    const std::size_t begin = group_starts[static_cast<std::size_t>(e)];
    const std::size_t end =
        e + 1 < edge_count ? group_starts[static_cast<std::size_t>(e + 1)] : half_edges.size();
    if (end - begin > 2) {
      throw std::invalid_argument("build_edge_topology: edge (" +
                                  std::to_string(half_edges[begin].key >> 32) + ", " +
                                  std::to_string(half_edges[begin].key & 0xffffffffU) + ") has " +
                                  std::to_string(end - begin) + " faces");
    }
    for (std::size_t i = begin; i < end; ++i) {
      const HalfEdge& h = half_edges[i];
      const int slot = static_cast<int>(i - begin);
      topology.edge_faces(e, slot) = h.face;
      topology.edge_opposite(e, slot) = faces(h.face, h.corner);
      topology.face_edges(h.face, h.corner) = static_cast<int>(e);
    }
    const HalfEdge& first = half_edges[begin];
    topology.edges(e, 0) = faces(first.face, (first.corner + 1) % 3);
    topology.edges(e, 1) = faces(first.face, (first.corner + 2) % 3);
  }
  return topology;
}

}  // namespace balloon
