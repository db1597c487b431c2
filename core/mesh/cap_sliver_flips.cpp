#include "mesh/cap_sliver_flips.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

using Corner = Eigen::Vector3d;

double smallest_angle(const Positions& vertices, const Eigen::Vector3i& face) {
  const std::array<double, 3> angles = corner_angles_deg(vertices, face);
  return *std::min_element(angles.begin(), angles.end());
}

Corner face_normal(const Positions& vertices, const Eigen::Vector3i& face) {
  const Corner a = vertices.row(face[0]).transpose();
  return (Corner(vertices.row(face[1]).transpose()) - a).cross(Corner(vertices.row(face[2]).transpose()) - a);
}

/// Directed edge (from, to) as one key.
long long edge_key(int from, int to) { return (static_cast<long long>(from) << 32) | static_cast<unsigned>(to); }

}  // namespace

CapSliverFlips flip_cap_slivers(const TriMesh& mesh, double sliver_angle_deg) {
  CapSliverFlips out;
  out.faces = mesh.faces;
  const Positions& vertices = mesh.vertices;
  // Almost every mesh has no sliver at all: one pass of angles, and no edge map, for those.
  if (min_angle_deg(vertices, out.faces) >= sliver_angle_deg) return out;

  std::unordered_map<long long, int> face_of_edge;  // directed edge -> the face that traverses it
  auto index_face = [&](int f, bool add) {
    for (int k = 0; k < 3; ++k) {
      const long long key = edge_key(out.faces(f, k), out.faces(f, (k + 1) % 3));
      if (add) face_of_edge[key] = f;
      else face_of_edge.erase(key);
    }
  };
  for (int f = 0; f < out.faces.rows(); ++f) index_face(f, true);

  // Each flip raises the pair's smallest angle, so no pair returns to an earlier state; the pass bound
  // only guards against meshes that are not what the contract asks.
  for (int pass = 0; pass < 8; ++pass) {
    bool flipped = false;
    for (int f = 0; f < out.faces.rows(); ++f) {
      const Eigen::Vector3i cap = out.faces.row(f).transpose();
      const std::array<double, 3> angles = corner_angles_deg(vertices, cap);
      const double cap_smallest = *std::min_element(angles.begin(), angles.end());
      if (cap_smallest >= sliver_angle_deg) continue;
      const int obtuse = static_cast<int>(std::max_element(angles.begin(), angles.end()) - angles.begin());
      if (angles[static_cast<size_t>(obtuse)] <= 90.0) continue;  // a needle: no diagonal to swap
      const int m = cap[obtuse], a = cap[(obtuse + 1) % 3], b = cap[(obtuse + 2) % 3];
      const auto across = face_of_edge.find(edge_key(b, a));
      if (across == face_of_edge.end()) continue;
      const int g = across->second;
      const Eigen::Vector3i neighbour = out.faces.row(g).transpose();
      int o = -1;
      for (int k = 0; k < 3; ++k)
        if (neighbour[k] != a && neighbour[k] != b) o = neighbour[k];
      if (o < 0 || o == m || face_of_edge.count(edge_key(m, o)) || face_of_edge.count(edge_key(o, m))) continue;
      const Eigen::Vector3i first(m, a, o), second(o, b, m);
      const Corner n_neighbour = face_normal(vertices, neighbour);
      if (face_normal(vertices, first).dot(n_neighbour) <= 0.0 || face_normal(vertices, second).dot(n_neighbour) <= 0.0)
        continue;
      const double before = std::min(cap_smallest, smallest_angle(vertices, neighbour));
      if (std::min(smallest_angle(vertices, first), smallest_angle(vertices, second)) <= before) continue;
      index_face(f, false);
      index_face(g, false);
      out.faces.row(f) = first.transpose();
      out.faces.row(g) = second.transpose();
      index_face(f, true);
      index_face(g, true);
      out.flipped_pairs.push_back({f, g});
      flipped = true;
    }
    if (!flipped) break;
  }
  return out;
}

}  // namespace balloon
