#pragma once
/// Distance from points to a triangle surface (the design error metric), and the rigid alignment that
/// takes away the arbitrary rigid placement of an inflated shape before it is measured.
#include <Eigen/Core>
#include <memory>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Summary of point-to-surface distances.
struct SurfaceDistanceStats {
  double avg_mm = 0.0;        ///< mean over the points of the distance to the closest surface point (mm)
  double max_mm = 0.0;        ///< largest such distance (mm)
  double rms_mm = 0.0;        ///< root mean square distance (mm)
  double bbox_diag_mm = 0.0;  ///< bounding-box diagonal of the surface (mm)
  double avg_rel = 0.0;       ///< avg_mm / bbox_diag_mm
  double max_rel = 0.0;       ///< max_mm / bbox_diag_mm
};

/// Closest-point queries against one fixed triangle surface (e.g. the design target). The AABB tree is
/// built once in the constructor (O(#F log #F)); each query is then about O(log #F). Queries are const
/// and may run concurrently. Movable, not copyable.
class SurfaceDistance {
 public:
  /// surface: #V by 3 positions (mm) and #F by 3 faces; needs at least one non-degenerate triangle
  /// (throws std::invalid_argument otherwise).
  explicit SurfaceDistance(const TriMesh& surface);
  ~SurfaceDistance();
  SurfaceDistance(SurfaceDistance&&) noexcept;
  SurfaceDistance& operator=(SurfaceDistance&&) noexcept;
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  /// Bounding-box diagonal of the surface (mm).
  double bbox_diagonal_mm() const;
  /// #P distances (mm) from each row of points (#P by 3, mm) to the closest point on the surface.
  Eigen::VectorXd distances(const Positions& points) const;
  /// Closest surface points (#P by 3, mm) and, if asked, their distances (#P, mm) and faces (#P).
  void closest_points(const Positions& points, Positions& closest, Eigen::VectorXd* distances = nullptr,
                      Eigen::VectorXi* faces = nullptr) const;
  /// Average / maximum / RMS distance of the points, in mm and relative to the bbox diagonal.
  SurfaceDistanceStats stats(const Positions& points) const;
  /// stats() after rigidly aligning `points` onto `reference_points` (same count and order, e.g. the
  /// target's own vertices for an inflated shape on the target's connectivity); see rigid_align_to().
  /// This is the design error metric: the rigid placement of an inflated balloon is arbitrary.
  SurfaceDistanceStats aligned_stats(const Positions& points, const Positions& reference_points) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// A proper rigid motion x -> rotation * x + translation (no scaling, no reflection).
struct RigidTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  /// The transformed #P by 3 positions.
  Positions apply(const Positions& points) const;
};

/// The rotation and translation minimizing sum_i |R p_i + t - q_i|^2 over corresponding rows of
/// points (p) and reference_points (q), both #P by 3 (mm), P >= 3 (Kabsch / orthogonal Procrustes; a
/// reflection is never returned). Throws std::invalid_argument if the shapes differ.
RigidTransform rigid_alignment(const Positions& points, const Positions& reference_points);
/// `points` moved by rigid_alignment(points, reference_points).
Positions rigid_align_to(const Positions& points, const Positions& reference_points);

}  // namespace balloon
