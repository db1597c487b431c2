#include "design/mold.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <numbers>
#include <queue>
#include <string>
#include <unordered_map>
#include <vector>

#include "design/nozzle.hpp"
#include "mesh/self_intersection.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

using Vector3d = Eigen::Vector3d;

Vector3d position(const TriMesh& mesh, int v) { return mesh.vertices.row(v).transpose(); }

/// Face neighbours across each edge (the faces sharing an edge with f), from the edge topology.
std::vector<std::vector<int>> face_neighbours(const TriMesh& mesh) {
  const EdgeTopology topology = build_edge_topology(mesh.faces, mesh.vertex_count());
  std::vector<std::vector<int>> out(static_cast<size_t>(mesh.face_count()));
  for (Eigen::Index e = 0; e < topology.edge_faces.rows(); ++e) {
    const int f0 = topology.edge_faces(e, 0), f1 = topology.edge_faces(e, 1);
    if (f0 < 0 || f1 < 0) continue;
    out[static_cast<size_t>(f0)].push_back(f1);
    out[static_cast<size_t>(f1)].push_back(f0);
  }
  return out;
}

/// Marks as removed every kept face outside the largest connected set of kept faces.
void keep_largest_component(const std::vector<std::vector<int>>& neighbours, std::vector<char>& removed) {
  const int n = static_cast<int>(removed.size());
  std::vector<int> component(static_cast<size_t>(n), -1);
  std::vector<int> sizes;
  for (int seed = 0; seed < n; ++seed) {
    if (removed[static_cast<size_t>(seed)] || component[static_cast<size_t>(seed)] >= 0) continue;
    const int id = static_cast<int>(sizes.size());
    sizes.push_back(0);
    std::queue<int> queue;
    queue.push(seed);
    component[static_cast<size_t>(seed)] = id;
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop();
      ++sizes.back();
      for (const int g : neighbours[static_cast<size_t>(f)]) {
        if (removed[static_cast<size_t>(g)] || component[static_cast<size_t>(g)] >= 0) continue;
        component[static_cast<size_t>(g)] = id;
        queue.push(g);
      }
    }
  }
  if (sizes.empty()) return;
  const int largest = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  for (int f = 0; f < n; ++f) {
    if (!removed[static_cast<size_t>(f)] && component[static_cast<size_t>(f)] != largest) removed[static_cast<size_t>(f)] = 1;
  }
}

}  // namespace

Result<TriMesh> build_mold(const TriMesh& rest, const Eigen::Vector3d& nozzle_center, double tube_radius_mm,
                           double tube_length_mm) {
  if (!(tube_radius_mm > 0.0) || !std::isfinite(tube_radius_mm) || !(tube_length_mm > 0.0) ||
      !std::isfinite(tube_length_mm)) {
    return fail("mold: tube radius and length must be finite and > 0 mm");
  }
  TriMesh checked = rest;
  auto report = validate_balloon_mesh(checked);
  if (!report) return fail("mold: the rest shape is not a valid closed mesh: " + report.error());
  if (report->flipped || report->removed_unreferenced_vertices > 0) {
    return fail("mold: the rest shape must be oriented outwards with no unused vertex");
  }
  NozzleSpec spec;
  spec.center = nozzle_center;
  spec.radius_mm = tube_radius_mm;
  auto nozzle = select_nozzle(rest, spec);
  if (!nozzle) return fail("mold: " + nozzle.error());
  const Vector3d nozzle_point = nozzle->center, nozzle_axis = nozzle->axis;
  const int center_vertex = nozzle->center_vertex;

  // Faces to remove: grown from the nozzle vertex through faces whose centroid is inside the cylinder
  // of radius R about the axis and within R of the nozzle along it (so the far side is never reached).
  const int face_count = rest.face_count();
  const auto neighbours = face_neighbours(rest);
  std::vector<char> removed(static_cast<size_t>(face_count), 0);
  std::queue<int> queue;
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (rest.faces(f, k) == center_vertex && !removed[static_cast<size_t>(f)]) {
        removed[static_cast<size_t>(f)] = 1;
        queue.push(f);
      }
    }
  }
  auto inside = [&](int f) {
    const Vector3d centroid =
        (position(rest, rest.faces(f, 0)) + position(rest, rest.faces(f, 1)) + position(rest, rest.faces(f, 2))) / 3.0;
    const Vector3d d = centroid - nozzle_point;
    const double along = d.dot(nozzle_axis);
    return (d - along * nozzle_axis).norm() < tube_radius_mm && std::abs(along) < tube_radius_mm;
  };
  while (!queue.empty()) {
    const int f = queue.front();
    queue.pop();
    for (const int g : neighbours[static_cast<size_t>(f)]) {
      if (removed[static_cast<size_t>(g)] || !inside(g)) continue;
      removed[static_cast<size_t>(g)] = 1;
      queue.push(g);
    }
  }

  // The hole must be one simple loop: drop islands, then widen the hole at any pinched boundary vertex.
  std::vector<int> loop;
  for (int attempt = 0; attempt < 8 && loop.empty(); ++attempt) {
    keep_largest_component(neighbours, removed);
    std::unordered_map<int, int> next;  // boundary half-edge a -> b of a kept face whose neighbour is removed
    std::vector<int> pinched;
    const EdgeTopology topology = build_edge_topology(rest.faces, rest.vertex_count());
    for (Eigen::Index e = 0; e < topology.edges.rows(); ++e) {
      const int f0 = topology.edge_faces(e, 0), f1 = topology.edge_faces(e, 1);
      const bool r0 = removed[static_cast<size_t>(f0)], r1 = removed[static_cast<size_t>(f1)];
      if (r0 == r1) continue;
      // Face f0 runs a -> b; the kept face owns the boundary half-edge in its own direction.
      const int a = topology.edges(e, 0), b = topology.edges(e, 1);
      const int from = r1 ? a : b, to = r1 ? b : a;
      if (!next.emplace(from, to).second) pinched.push_back(from);
    }
    if (next.empty()) return fail("mold: the tube radius removes the whole surface");
    if (pinched.empty()) {
      // Walk the loop from its smallest vertex (deterministic start).
      int start = next.begin()->first;
      for (const auto& [from, to] : next) start = std::min(start, from);
      std::vector<int> walk{start};
      for (int v = next.at(start); v != start && static_cast<int>(walk.size()) <= static_cast<int>(next.size());
           v = next.at(v)) {
        walk.push_back(v);
      }
      if (walk.size() == next.size()) {
        loop = std::move(walk);
        break;
      }
      pinched.push_back(start);  // several loops: widen and retry
    }
    for (int f = 0; f < face_count; ++f) {
      for (int k = 0; k < 3; ++k) {
        if (std::find(pinched.begin(), pinched.end(), rest.faces(f, k)) != pinched.end()) removed[static_cast<size_t>(f)] = 1;
      }
    }
  }
  if (loop.empty()) {
    return fail("mold: the surface around the nozzle does not leave a single round hole for the tube; "
                "try a smaller tube radius or another nozzle position");
  }

  // Keep the vertices of the kept faces, in their original order.
  std::vector<int> new_index(static_cast<size_t>(rest.vertex_count()), -1);
  std::vector<Eigen::Vector3i> faces;
  std::vector<Vector3d> vertices;
  for (int f = 0; f < face_count; ++f) {
    if (removed[static_cast<size_t>(f)]) continue;
    for (int k = 0; k < 3; ++k) new_index[static_cast<size_t>(rest.faces(f, k))] = 0;
  }
  for (int v = 0; v < rest.vertex_count(); ++v) {
    if (new_index[static_cast<size_t>(v)] < 0) continue;
    new_index[static_cast<size_t>(v)] = static_cast<int>(vertices.size());
    vertices.push_back(position(rest, v));
  }
  for (int f = 0; f < face_count; ++f) {
    if (removed[static_cast<size_t>(f)]) continue;
    faces.emplace_back(new_index[static_cast<size_t>(rest.faces(f, 0))], new_index[static_cast<size_t>(rest.faces(f, 1))],
                       new_index[static_cast<size_t>(rest.faces(f, 2))]);
  }

  // The tube follows the hole itself: its axis is the loop's Newell normal (the area vector of the
  // loop polygon, turned outwards), its centre the loop's arc-length centroid. This stays sensible on
  // coarse or sliver-ridden surfaces where the averaged normal does not see the loop as round.
  const int m = static_cast<int>(loop.size());
  Vector3d newell = Vector3d::Zero(), c = Vector3d::Zero();
  double perimeter = 0.0;
  for (int i = 0; i < m; ++i) {
    const Vector3d p = position(rest, loop[static_cast<size_t>(i)]);
    const Vector3d q = position(rest, loop[static_cast<size_t>((i + 1) % m)]);
    newell += p.cross(q);
    const double length = (q - p).norm();
    c += 0.5 * length * (p + q);
    perimeter += length;
  }
  if (!(perimeter > 0.0) || !(newell.norm() > 0.0)) return fail("mold: the hole around the nozzle is degenerate");
  c /= perimeter;
  Vector3d axis = newell.normalized();
  if (axis.dot(nozzle->axis) < 0.0) axis = -axis;

  // Frame about the axis; the loop's angular direction around it; circle targets spaced by arc length
  // along the loop, so the rings stay simple even if the loop is wavy.
  const Vector3d e1 = (std::abs(axis.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY()).cross(axis).normalized();
  const Vector3d e2 = axis.cross(e1);
  std::vector<double> along(static_cast<size_t>(m)), arc(static_cast<size_t>(m) + 1, 0.0);
  double winding = 0.0, top = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) {
    const Vector3d p = position(rest, loop[static_cast<size_t>(i)]) - c;
    const Vector3d q = position(rest, loop[static_cast<size_t>((i + 1) % m)]) - c;
    along[static_cast<size_t>(i)] = p.dot(axis);
    top = std::max(top, along[static_cast<size_t>(i)]);
    arc[static_cast<size_t>(i) + 1] = arc[static_cast<size_t>(i)] + (q - p).norm();
    const double a0 = std::atan2(p.dot(e2), p.dot(e1)), a1 = std::atan2(q.dot(e2), q.dot(e1));
    double step = a1 - a0;
    while (step > std::numbers::pi) step -= 2.0 * std::numbers::pi;
    while (step <= -std::numbers::pi) step += 2.0 * std::numbers::pi;
    winding += step;
  }
  if (std::abs(std::abs(winding) - 2.0 * std::numbers::pi) > 0.5) {
    return fail("mold: the hole around the nozzle does not wind once around the tube axis");
  }
  const double direction = winding > 0.0 ? 1.0 : -1.0;
  const Vector3d p0 = position(rest, loop[0]) - c;
  const double start_angle = std::atan2(p0.dot(e2), p0.dot(e1));
  const double end = top + tube_length_mm;
  const double mean_edge = arc[static_cast<size_t>(m)] / m;
  const int rings = std::clamp(static_cast<int>(std::ceil(tube_length_mm / std::max(mean_edge, 1e-9))), 3, 40);
  constexpr double BLEND_RINGS = 2.0;

  std::vector<int> previous(static_cast<size_t>(m));
  for (int i = 0; i < m; ++i) previous[static_cast<size_t>(i)] = new_index[static_cast<size_t>(loop[static_cast<size_t>(i)])];
  for (int k = 1; k <= rings; ++k) {
    const double s = static_cast<double>(k) / rings;
    const double w = std::min(1.0, k / BLEND_RINGS);
    std::vector<int> ring(static_cast<size_t>(m));
    for (int i = 0; i < m; ++i) {
      const Vector3d p = position(rest, loop[static_cast<size_t>(i)]) - c;
      const Vector3d radial_loop = p - along[static_cast<size_t>(i)] * axis;
      const double angle = start_angle + direction * 2.0 * std::numbers::pi * arc[static_cast<size_t>(i)] / arc[static_cast<size_t>(m)];
      const Vector3d radial_circle = tube_radius_mm * (std::cos(angle) * e1 + std::sin(angle) * e2);
      const double height = along[static_cast<size_t>(i)] + s * (end - along[static_cast<size_t>(i)]);
      ring[static_cast<size_t>(i)] = static_cast<int>(vertices.size());
      vertices.push_back(c + (1.0 - w) * radial_loop + w * radial_circle + height * axis);
    }
    // The loop runs a -> b in the kept faces: the wall uses b -> a so orientations agree.
    for (int i = 0; i < m; ++i) {
      const int j = (i + 1) % m;
      faces.emplace_back(previous[static_cast<size_t>(j)], previous[static_cast<size_t>(i)], ring[static_cast<size_t>(i)]);
      faces.emplace_back(previous[static_cast<size_t>(j)], ring[static_cast<size_t>(i)], ring[static_cast<size_t>(j)]);
    }
    previous = std::move(ring);
  }
  const int cap = static_cast<int>(vertices.size());
  vertices.push_back(c + end * axis);
  for (int i = 0; i < m; ++i) {
    faces.emplace_back(previous[static_cast<size_t>((i + 1) % m)], previous[static_cast<size_t>(i)], cap);
  }

  TriMesh mold;
  mold.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (size_t v = 0; v < vertices.size(); ++v) mold.vertices.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  mold.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) mold.faces.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();

  TriMesh final_check = mold;
  auto mold_report = validate_balloon_mesh(final_check);
  if (!mold_report) return fail("mold: the joined tube does not give a valid closed mesh: " + mold_report.error());
  if (mold_report->flipped) return fail("mold: the joined tube turned the mesh inside out");
  if (mold_report->genus != report->genus) return fail("mold: joining the tube changed the genus");
  if (mesh_self_intersects(mold) && !mesh_self_intersects(rest)) {
    return fail("mold: the tube intersects the balloon surface; try a shorter, narrower tube or another nozzle position");
  }
  return mold;
}

}  // namespace balloon
