#include "mesh/mesh_checks.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh_geometry.hpp"

namespace balloon {

namespace {

/// Relative volume below which a closed surface encloses nothing (e.g. two faces glued back to back).
constexpr double ZERO_VOLUME_RELATIVE = 1e-12;

std::string str(int i) { return std::to_string(i); }

std::string fmt(double x) {
  std::ostringstream out;
  out.precision(6);
  out << x;
  return out.str();
}

// Built by appending: GCC 12 gives a false -Wrestrict on "(" + std::string (its bug 105329).
std::string tuple_of(std::initializer_list<int> values) {
  std::string out = "(";
  for (const int v : values) {
    if (out.size() > 1) out += ", ";
    out += std::to_string(v);
  }
  out += ')';
  return out;
}

std::string triple(int a, int b, int c) { return tuple_of({a, b, c}); }

/// Union-find with path halving; small and local to the checks.
class DisjointSets {
 public:
  explicit DisjointSets(int n) { reset(n); }
  /// n singletons again, keeping the storage (one set per vertex fan, 100k times).
  void reset(int n) {
    m_parent.resize(static_cast<std::size_t>(n));
    std::iota(m_parent.begin(), m_parent.end(), 0);
  }
  int find(int i) {
    while (m_parent[static_cast<std::size_t>(i)] != i) {
      auto& p = m_parent[static_cast<std::size_t>(i)];
      p = m_parent[static_cast<std::size_t>(p)];
      i = p;
    }
    return i;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) m_parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<int> m_parent;
};

/// One directed edge from -> to of face `face`.
struct HalfEdge {
  std::uint64_t key;  // (min vertex << 32) | max vertex: the undirected edge
  int from;
  int to;
  int face;
};

}  // namespace

Result<MeshCheckReport> validate_balloon_mesh(TriMesh& mesh) {
  const int vertex_count = mesh.vertex_count();
  const int face_count = mesh.face_count();
  const Positions& x = mesh.vertices;
  const Faces& faces = mesh.faces;

  if (face_count == 0) {
    return fail(vertex_count == 0 ? "empty mesh: no vertices and no faces"
                                  : "empty mesh: " + str(vertex_count) + " vertices but no faces");
  }
  if (vertex_count == 0) return fail("empty mesh: " + str(face_count) + " faces but no vertices");

  for (int v = 0; v < vertex_count; ++v) {
    if (!x.row(v).allFinite()) {
      return fail("non-finite coordinate at vertex " + str(v) + ": (" + fmt(x(v, 0)) + ", " +
                  fmt(x(v, 1)) + ", " + fmt(x(v, 2)) + ")");
    }
  }
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      if (faces(f, k) < 0 || faces(f, k) >= vertex_count) {
        return fail("face " + str(f) + " refers to vertex " + str(faces(f, k)) +
                    ", out of range 0.." + str(vertex_count - 1));
      }
    }
  }
  for (int f = 0; f < face_count; ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (a == b || b == c || c == a) {
      return fail("degenerate face " + str(f) + ": vertex " + str(a == b || a == c ? a : b) +
                  " appears twice in " + triple(a, b, c));
    }
  }

  // Size of the referenced part: stray far-away vertices must not make real triangles look tiny.
  std::vector<char> referenced(static_cast<std::size_t>(vertex_count), 0);
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) referenced[static_cast<std::size_t>(faces(f, k))] = 1;
  }
  Eigen::RowVector3d lo = Eigen::RowVector3d::Constant(INFINITY);
  Eigen::RowVector3d hi = Eigen::RowVector3d::Constant(-INFINITY);
  for (int v = 0; v < vertex_count; ++v) {
    if (!referenced[static_cast<std::size_t>(v)]) continue;
    lo = lo.cwiseMin(x.row(v));
    hi = hi.cwiseMax(x.row(v));
  }
  const double diagonal = (hi - lo).norm();

  const double min_area = ZERO_AREA_RELATIVE * diagonal * diagonal;
  for (int f = 0; f < face_count; ++f) {
    const Eigen::RowVector3d a = x.row(faces(f, 0));
    const double area = 0.5 * (x.row(faces(f, 1)) - a).cross(x.row(faces(f, 2)) - a).norm();
    if (!(area >= min_area) || area == 0.0) {
      return fail("zero-area triangle: face " + str(f) + " " +
                  triple(faces(f, 0), faces(f, 1), faces(f, 2)) + " has area " + fmt(area) +
                  " mm^2 (bounding-box diagonal " + fmt(diagonal) + " mm)");
    }
  }

  // Half-edges sorted by undirected edge, then face: each group is one edge with all its faces. They
  // are bucketed by the edge's lower vertex first (linear), so only each vertex's few edges are sorted.
  auto lower_vertex = [&](int f, int k) {
    return static_cast<std::size_t>(std::min(faces(f, k), faces(f, (k + 1) % 3)));
  };
  std::vector<int> bucket_starts(static_cast<std::size_t>(vertex_count) + 1, 0);
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) ++bucket_starts[lower_vertex(f, k) + 1];
  }
  std::partial_sum(bucket_starts.begin(), bucket_starts.end(), bucket_starts.begin());
  std::vector<HalfEdge> half_edges(static_cast<std::size_t>(3 * face_count));
  {
    std::vector<int> fill(bucket_starts.begin(), bucket_starts.end() - 1);
    for (int f = 0; f < face_count; ++f) {
      for (int k = 0; k < 3; ++k) {
        const int from = faces(f, k), to = faces(f, (k + 1) % 3);
        const auto key = (static_cast<std::uint64_t>(std::min(from, to)) << 32) |
                         static_cast<std::uint64_t>(std::max(from, to));
        half_edges[static_cast<std::size_t>(fill[lower_vertex(f, k)]++)] = {key, from, to, f};
      }
    }
  }
  for (int v = 0; v < vertex_count; ++v) {
    std::sort(half_edges.begin() + bucket_starts[static_cast<std::size_t>(v)],
              half_edges.begin() + bucket_starts[static_cast<std::size_t>(v) + 1],
              [](const HalfEdge& p, const HalfEdge& q) { return p.key != q.key ? p.key < q.key : p.face < q.face; });
  }
  std::vector<std::size_t> group_starts;
  for (std::size_t i = 0; i < half_edges.size(); ++i) {
    if (i == 0 || half_edges[i].key != half_edges[i - 1].key) group_starts.push_back(i);
  }
  group_starts.push_back(half_edges.size());
  const std::size_t edge_count = group_starts.size() - 1;

  // Of each kind of edge problem, report the one whose first face has the lowest index.
  std::size_t worst_non_manifold = edge_count, worst_boundary = edge_count, worst_orientation = edge_count;
  auto lower_face = [&](std::size_t candidate, std::size_t current) {
    return current == edge_count ||
           half_edges[group_starts[candidate]].face < half_edges[group_starts[current]].face;
  };
  for (std::size_t e = 0; e < edge_count; ++e) {
    const std::size_t begin = group_starts[e], size = group_starts[e + 1] - begin;
    if (size > 2 && lower_face(e, worst_non_manifold)) worst_non_manifold = e;
    if (size == 1 && lower_face(e, worst_boundary)) worst_boundary = e;
    if (size == 2 && half_edges[begin].from == half_edges[begin + 1].from &&
        lower_face(e, worst_orientation)) {
      worst_orientation = e;
    }
  }
  auto edge_name = [&](std::size_t e) {
    const HalfEdge& h = half_edges[group_starts[e]];
    return tuple_of({h.from, h.to});
  };
  if (worst_non_manifold != edge_count) {
    const std::size_t begin = group_starts[worst_non_manifold];
    const std::size_t size = group_starts[worst_non_manifold + 1] - begin;
    // A face bomb can put 300k faces on one edge: name the first few, count the rest.
    constexpr std::size_t NAMED_FACES = 4;
    std::string face_list;
    for (std::size_t i = begin; i < begin + std::min(size, NAMED_FACES); ++i) {
      face_list += (i == begin ? "" : ", ") + str(half_edges[i].face);
    }
    if (size > NAMED_FACES) face_list += " and " + std::to_string(size - NAMED_FACES) + " more";
    return fail("non-manifold edge " + edge_name(worst_non_manifold) + " shared by " +
                std::to_string(size) + " faces (faces " + face_list + ")");
  }
  if (worst_boundary != edge_count) {
    return fail("open boundary: edge " + edge_name(worst_boundary) + " of face " +
                str(half_edges[group_starts[worst_boundary]].face) + " has only one face");
  }

  // Every edge now has exactly two faces. A vertex is manifold when its faces, joined across the
  // edges at the vertex, form one fan (one cycle around it), not several fans touching at a point.
  std::vector<int> fan_offsets(static_cast<std::size_t>(vertex_count) + 1, 0);
  for (int f = 0; f < face_count; ++f) {
    for (int k = 0; k < 3; ++k) ++fan_offsets[static_cast<std::size_t>(faces(f, k)) + 1];
  }
  std::partial_sum(fan_offsets.begin(), fan_offsets.end(), fan_offsets.begin());
  std::vector<int> fan_faces(static_cast<std::size_t>(3 * face_count));
  {
    std::vector<int> fill(fan_offsets.begin(), fan_offsets.end() - 1);
    for (int f = 0; f < face_count; ++f) {
      for (int k = 0; k < 3; ++k) fan_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(faces(f, k))]++)] = f;
    }
  }
  // (neighbour vertex, local face) of every face at a vertex, sorted: faces sharing an edge (v, w) are
  // neighbours. Sorted rather than searched, so a vertex with 100k faces (a cone's apex) costs
  // 100k log 100k, not 100k^2 (about 4 s at submit). Reused per vertex.
  std::vector<std::pair<int, int>> spokes;
  DisjointSets fans(0);
  for (int v = 0; v < vertex_count; ++v) {
    const int begin = fan_offsets[static_cast<std::size_t>(v)];
    const int degree = fan_offsets[static_cast<std::size_t>(v) + 1] - begin;
    if (degree == 0) continue;
    if (degree > MAX_VERTEX_DEGREE) {
      return fail("vertex " + str(v) + " has " + str(degree) + " triangles, more than the " +
                  str(MAX_VERTEX_DEGREE) + " a vertex may have (checking a wider fan for self-intersection " +
                  "takes minutes); remesh the surface around it");
    }
    fans.reset(degree);
    spokes.clear();
    for (int i = 0; i < degree; ++i) {
      const int f = fan_faces[static_cast<std::size_t>(begin + i)];
      for (int k = 0; k < 3; ++k)
        if (faces(f, k) != v) spokes.emplace_back(faces(f, k), i);
    }
    std::sort(spokes.begin(), spokes.end());
    for (std::size_t s = 1; s < spokes.size(); ++s)
      if (spokes[s].first == spokes[s - 1].first) fans.unite(spokes[s - 1].second, spokes[s].second);
    int fan_count = 0, other_face = -1;
    for (int i = 0; i < degree; ++i) {
      if (fans.find(i) == i) {
        ++fan_count;
        if (i != 0 && other_face < 0) other_face = fan_faces[static_cast<std::size_t>(begin + i)];
      }
    }
    if (fan_count > 1) {
      return fail("non-manifold vertex " + str(v) + ": its faces form " + str(fan_count) +
                  " separate fans (faces " + str(fan_faces[static_cast<std::size_t>(begin)]) + " and " +
                  str(other_face) + " meet only at this vertex)");
    }
  }

  DisjointSets components(face_count);
  for (std::size_t e = 0; e < edge_count; ++e) {
    components.unite(half_edges[group_starts[e]].face, half_edges[group_starts[e] + 1].face);
  }
  int component_count = 0, other_component_face = -1;
  for (int f = 0; f < face_count; ++f) {
    if (components.find(f) == f) {
      ++component_count;
      if (f != 0 && other_component_face < 0) other_component_face = f;
    }
  }
  if (component_count > 1) {
    return fail("several connected components: the mesh has " + str(component_count) +
                " (faces 0 and " + str(other_component_face) +
                " are not connected); a balloon must be one closed surface");
  }

  if (worst_orientation != edge_count) {
    const std::size_t begin = group_starts[worst_orientation];
    return fail("inconsistent orientation: faces " + str(half_edges[begin].face) + " and " +
                str(half_edges[begin + 1].face) + " both traverse edge " +
                edge_name(worst_orientation) + " in the same direction");
  }

  const double volume = enclosed_volume(x, faces);
  if (!(std::abs(volume) > ZERO_VOLUME_RELATIVE * diagonal * diagonal * diagonal)) {
    return fail("zero volume: the closed surface encloses " + fmt(volume) +
                " mm^3 (its faces lie back to back)");
  }

  // Valid: now clean up in place.
  MeshCheckReport report;
  std::vector<int> new_index(static_cast<std::size_t>(vertex_count), -1);
  int kept = 0;
  for (int v = 0; v < vertex_count; ++v) {
    if (referenced[static_cast<std::size_t>(v)]) new_index[static_cast<std::size_t>(v)] = kept++;
  }
  if (kept < vertex_count) {
    Positions compact(kept, 3);
    for (int v = 0; v < vertex_count; ++v) {
      if (new_index[static_cast<std::size_t>(v)] >= 0) compact.row(new_index[static_cast<std::size_t>(v)]) = x.row(v);
    }
    for (int f = 0; f < face_count; ++f) {
      for (int k = 0; k < 3; ++k) mesh.faces(f, k) = new_index[static_cast<std::size_t>(mesh.faces(f, k))];
    }
    mesh.vertices = std::move(compact);
    report.removed_unreferenced_vertices = vertex_count - kept;
    report.notes.push_back("removed " + str(vertex_count - kept) +
                           " vertices that no face uses (indices compacted)");
  }
  if (volume < 0.0) {
    mesh.faces.col(1).swap(mesh.faces.col(2));
    report.flipped = true;
    report.notes.push_back("the mesh was oriented inwards (volume " + fmt(volume) +
                           " mm^3); every face was reversed");
  }

  report.vertices = mesh.vertex_count();
  report.faces = mesh.face_count();
  report.edges = static_cast<int>(edge_count);
  report.genus = (2 - (report.vertices - report.edges + report.faces)) / 2;
  report.volume_mm3 = std::abs(volume);
  report.area_mm2 = surface_area(mesh.vertices, mesh.faces);
  report.bounding_box_diagonal_mm = diagonal;
  report.min_angle_deg = min_angle_deg(mesh.vertices, mesh.faces);
  return report;
}

}  // namespace balloon
