#pragma once
/// Rest-shape self-collision penalty (paper eq. 24): vertex pairs closer than eps_c that are not
/// geodesic neighbours get the cubic penalty k (eps_c - d)^3, found with a kd-tree (nanoflann).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon {

struct SelfCollisionOptions {
  /// eps_c (mm): pairs closer than this are penalized. 0: the mean rest edge length, so that a vertex
  /// passing through a sheet of triangles is always within eps_c of one of their corners.
  double contact_distance_mm = 0.0;
  /// eps_gd (mm): pairs whose edge-graph distance on the rest mesh is below this are never penalized.
  /// 0: 3 * eps_c (a smooth unfolded surface keeps such pairs farther apart than eps_c).
  double geodesic_exclusion_mm = 0.0;
  /// Pairs within this many edge rings of each other are never penalized, whatever their lengths.
  int exclusion_rings = 2;
  /// k (N/mm^2): W = k (eps_c - d)^3 is then an energy in N*mm.
  double stiffness = 1.0;
};

/// The penalty sum over active pairs (i, j) of k (eps_c - |x_i - x_j|)^3 (zero for |x_i - x_j| >= eps_c;
/// C2 at eps_c, >= 0), with gradient and Hessian.
///
/// Geodesic neighbours: the constructor runs, from every vertex of the REST mesh given to it, a
/// breadth-first search of `exclusion_rings` rings and a Dijkstra search over edge lengths limited to
/// eps_gd; the union is the vertex's excluded set (symmetric, stored sorted; memory about #V times the
/// vertices within eps_gd). Edge-graph distances over-estimate the true geodesic distance by at most
/// ~15% on a fair mesh, so the exclusion errs toward detecting more pairs. The sets are computed once:
/// they follow the connectivity, not the changing rest positions.
///
/// Cost: update() is the only search: one kd-tree build over #V points, O(#V log #V), and one radius
/// query per vertex (about 1-3 ms for 5k vertices). value/gradient/hessian_triplets cost O(#active
/// pairs) plus, for gradient, zeroing the 3#V output: nothing when no pair is near.
class SelfCollision {
 public:
  /// rest: the initial rest shape (mm, closed or open, any orientation). Throws std::invalid_argument
  /// on negative options or an out-of-range face index.
  explicit SelfCollision(const TriMesh& rest, const SelfCollisionOptions& options = {});

  double contact_distance_mm() const { return m_contact_distance; }
  double geodesic_exclusion_mm() const { return m_geodesic_exclusion; }
  double stiffness() const { return m_stiffness; }
  int vertex_count() const { return m_vertex_count; }
  /// Total size of the excluded sets (pairs counted twice): the memory the exclusion takes.
  long long excluded_pair_count() const { return static_cast<long long>(m_excluded.size()); }
  /// True if vertices i and j are geodesic neighbours (never a collision pair).
  bool excluded(int i, int j) const;

  /// Finds the pairs closer than eps_c at x (3#V flat, mm) that are not excluded, replacing the
  /// active set; returns how many. Call once per outer iteration (or line-search trial), before value.
  int update(Eigen::Ref<const Eigen::VectorXd> x);
  /// True if the last update() found a pair. O(1).
  bool any_active() const { return !m_pairs.empty(); }
  /// The pairs (i < j) found by the last update().
  const std::vector<std::array<int, 2>>& active_pairs() const { return m_pairs; }

  /// Penalty (N*mm) at x over the active pairs (each re-evaluated at x: 0 if now apart).
  double value(Eigen::Ref<const Eigen::VectorXd> x) const;
  /// dW/dx (3#V, N): `gradient` is resized and overwritten.
  void gradient(Eigen::Ref<const Eigen::VectorXd> x, Eigen::VectorXd& gradient) const;
  /// Appends the Hessian (N/mm) entries, rows/cols shifted by dof_offset. With project_psd the
  /// (negative) part across each pair's direction is dropped, leaving a PSD matrix.
  void hessian_triplets(Eigen::Ref<const Eigen::VectorXd> x, std::vector<Eigen::Triplet<double>>& triplets,
                        bool project_psd = false, int dof_offset = 0) const;

 private:
  int m_vertex_count = 0;
  double m_contact_distance = 0.0;
  double m_geodesic_exclusion = 0.0;
  double m_stiffness = 0.0;
  std::vector<int> m_excluded_offsets;  // CSR: excluded set of v is m_excluded[offsets[v], offsets[v+1])
  std::vector<int> m_excluded;
  std::vector<std::array<int, 2>> m_pairs;
};

}  // namespace balloon
