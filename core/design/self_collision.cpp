// The only file that includes nanoflann.
#include "design/self_collision.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>

namespace balloon {
namespace {

/// nanoflann's view of a flat 3#V position vector.
struct FlatPointCloud {
  const double* data;
  size_t count;
  size_t kdtree_get_point_count() const { return count; }
  double kdtree_get_pt(size_t i, size_t dim) const { return data[3 * i + dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, FlatPointCloud>,
                                                   FlatPointCloud, 3, unsigned>;

}  // namespace

SelfCollision::SelfCollision(const TriMesh& rest, const SelfCollisionOptions& options)
    : m_vertex_count(rest.vertex_count()), m_stiffness(options.stiffness) {
  if (options.contact_distance_mm < 0.0 || options.geodesic_exclusion_mm < 0.0 || options.exclusion_rings < 0 ||
      !(options.stiffness >= 0.0)) {
    throw std::invalid_argument("SelfCollision: options must be >= 0");
  }
  const int n = m_vertex_count;
  std::vector<std::vector<std::pair<int, double>>> neighbours(static_cast<size_t>(n));
  double edge_sum = 0.0;
  long long edge_terms = 0;
  for (int f = 0; f < rest.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = rest.faces(f, k), b = rest.faces(f, (k + 1) % 3);
      if (a < 0 || a >= n || b < 0 || b >= n) throw std::invalid_argument("SelfCollision: bad face index");
      const double length = (rest.vertices.row(a) - rest.vertices.row(b)).norm();
      neighbours[static_cast<size_t>(a)].emplace_back(b, length);
      neighbours[static_cast<size_t>(b)].emplace_back(a, length);
      edge_sum += length;
      ++edge_terms;
    }
  }
  const double mean_edge = edge_terms > 0 ? edge_sum / static_cast<double>(edge_terms) : 0.0;
  m_contact_distance = options.contact_distance_mm > 0.0 ? options.contact_distance_mm : mean_edge;
  m_geodesic_exclusion =
      options.geodesic_exclusion_mm > 0.0 ? options.geodesic_exclusion_mm : 3.0 * m_contact_distance;

  // Per vertex: rings by BFS, then Dijkstra limited to eps_gd; marks reset through the touched list.
  m_excluded_offsets.assign(static_cast<size_t>(n) + 1, 0);
  std::vector<double> distance(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int> ring(static_cast<size_t>(n), -1);
  std::vector<int> touched, found;
  using Item = std::pair<double, int>;
  for (int source = 0; source < n; ++source) {
    touched.clear();
    found.clear();
    std::vector<int> frontier{source};
    ring[static_cast<size_t>(source)] = 0;
    touched.push_back(source);
    for (int r = 1; r <= options.exclusion_rings && !frontier.empty(); ++r) {
      std::vector<int> next;
      for (const int v : frontier) {
        for (const auto& [w, length] : neighbours[static_cast<size_t>(v)]) {
          if (ring[static_cast<size_t>(w)] >= 0) continue;
          ring[static_cast<size_t>(w)] = r;
          touched.push_back(w);
          next.push_back(w);
        }
      }
      frontier = std::move(next);
    }
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    distance[static_cast<size_t>(source)] = 0.0;
    queue.emplace(0.0, source);
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > distance[static_cast<size_t>(v)]) continue;
      for (const auto& [w, length] : neighbours[static_cast<size_t>(v)]) {
        const double candidate = d + length;
        if (candidate >= m_geodesic_exclusion || candidate >= distance[static_cast<size_t>(w)]) continue;
        if (std::isinf(distance[static_cast<size_t>(w)]) && ring[static_cast<size_t>(w)] < 0) touched.push_back(w);
        distance[static_cast<size_t>(w)] = candidate;
        queue.emplace(candidate, w);
      }
    }
    for (const int v : touched) {
      if (v != source) found.push_back(v);
      distance[static_cast<size_t>(v)] = std::numeric_limits<double>::infinity();
      ring[static_cast<size_t>(v)] = -1;
    }
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
    m_excluded.insert(m_excluded.end(), found.begin(), found.end());
    m_excluded_offsets[static_cast<size_t>(source) + 1] = static_cast<int>(m_excluded.size());
  }
}

bool SelfCollision::excluded(int i, int j) const {
  if (i == j) return true;
  const auto begin = m_excluded.begin() + m_excluded_offsets[static_cast<size_t>(i)];
  const auto end = m_excluded.begin() + m_excluded_offsets[static_cast<size_t>(i) + 1];
  return std::binary_search(begin, end, j);
}

int SelfCollision::update(Eigen::Ref<const Eigen::VectorXd> x) {
  if (x.size() != 3 * m_vertex_count) throw std::invalid_argument("SelfCollision: x has the wrong size");
  m_pairs.clear();
  if (m_vertex_count < 2 || m_stiffness == 0.0) return 0;
  const FlatPointCloud cloud{x.data(), static_cast<size_t>(m_vertex_count)};
  KdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  const double radius2 = m_contact_distance * m_contact_distance;  // L2_Simple works with squared distances
  std::vector<std::pair<unsigned, double>> matches;
  nanoflann::SearchParams params;
  params.sorted = false;
  for (int i = 0; i < m_vertex_count; ++i) {
    matches.clear();
    tree.radiusSearch(x.data() + 3 * i, radius2, matches, params);
    for (const auto& [j, d2] : matches) {
      const int jj = static_cast<int>(j);
      if (jj <= i || d2 >= radius2 || excluded(i, jj)) continue;
      m_pairs.push_back({i, jj});
    }
  }
  std::sort(m_pairs.begin(), m_pairs.end());  // deterministic order whatever the tree visits
  return static_cast<int>(m_pairs.size());
}

double SelfCollision::value(Eigen::Ref<const Eigen::VectorXd> x) const {
  double total = 0.0;
  for (const auto& [i, j] : m_pairs) {
    const double d = (x.segment<3>(3 * i) - x.segment<3>(3 * j)).norm();
    if (d < m_contact_distance) total += m_stiffness * std::pow(m_contact_distance - d, 3);
  }
  return total;
}

void SelfCollision::gradient(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& gradient) const {
  gradient.setZero(3 * m_vertex_count);
  for (const auto& [i, j] : m_pairs) {
    const Eigen::Vector3d delta = x.segment<3>(3 * i) - x.segment<3>(3 * j);
    const double d = delta.norm();
    if (!(d < m_contact_distance) || !(d > 0.0)) continue;  // coincident points have no direction
    const double gap = m_contact_distance - d;
    const Eigen::Vector3d g = -3.0 * m_stiffness * gap * gap * delta / d;  // dW/dd * dd/dx_i
    gradient.segment<3>(3 * i) += g;
    gradient.segment<3>(3 * j) -= g;
  }
}

void SelfCollision::hessian_triplets(Eigen::Ref<const Eigen::VectorXd> x,
                                     std::vector<Eigen::Triplet<double>>& triplets, bool project_psd,
                                     int dof_offset) const {
  for (const auto& [i, j] : m_pairs) {
    const Eigen::Vector3d delta = x.segment<3>(3 * i) - x.segment<3>(3 * j);
    const double d = delta.norm();
    if (!(d < m_contact_distance) || !(d > 0.0)) continue;
    const double gap = m_contact_distance - d;
    const Eigen::Vector3d n = delta / d;
    // W(d): W'' n n^T + W'/d (I - n n^T), with W' = -3k gap^2 <= 0 and W'' = 6k gap >= 0.
    const double along = 6.0 * m_stiffness * gap;
    const double across = project_psd ? 0.0 : -3.0 * m_stiffness * gap * gap / d;
    const Eigen::Matrix3d block = along * n * n.transpose() + across * (Eigen::Matrix3d::Identity() - n * n.transpose());
    const int vertices[2] = {i, j};
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        const double sign = a == b ? 1.0 : -1.0;
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) {
            triplets.emplace_back(dof_offset + 3 * vertices[a] + r, dof_offset + 3 * vertices[b] + c, sign * block(r, c));
          }
        }
      }
    }
  }
}

}  // namespace balloon
