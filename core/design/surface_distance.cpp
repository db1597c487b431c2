// The only file that includes CGAL's AABB tree (remeshing lives in target_preparation.cpp).
#include "design/surface_distance.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace balloon {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

}  // namespace

struct SurfaceDistance::Impl {
  std::vector<Triangle> triangles;  // the tree refers to these: they never move once the tree is built
  std::vector<int> face_of_triangle;
  Tree tree;
  double bbox_diagonal = 0.0;
};

SurfaceDistance::SurfaceDistance(const TriMesh& surface) : m_impl(std::make_unique<Impl>()) {
  Impl& impl = *m_impl;
  impl.triangles.reserve(static_cast<size_t>(surface.face_count()));
  for (int f = 0; f < surface.face_count(); ++f) {
    const auto p = [&](int c) {
      const int v = surface.faces(f, c);
      if (v < 0 || v >= surface.vertex_count()) throw std::invalid_argument("SurfaceDistance: bad face index");
      return Point(surface.vertices(v, 0), surface.vertices(v, 1), surface.vertices(v, 2));
    };
    Triangle t(p(0), p(1), p(2));
    // Degenerate triangles would break CGAL's squared-distance code; they add nothing to the surface.
    if (t.is_degenerate()) continue;
    impl.triangles.push_back(t);
    impl.face_of_triangle.push_back(f);
  }
  if (impl.triangles.empty()) throw std::invalid_argument("SurfaceDistance: no non-degenerate triangle");
  impl.tree.insert(impl.triangles.cbegin(), impl.triangles.cend());
  impl.tree.build();
  // Build the internal kd-tree now so that later const queries never build lazily (thread safety).
  impl.tree.accelerate_distance_queries();
  const Eigen::RowVector3d lo = surface.vertices.colwise().minCoeff(), hi = surface.vertices.colwise().maxCoeff();
  impl.bbox_diagonal = (hi - lo).norm();
}

SurfaceDistance::~SurfaceDistance() = default;
SurfaceDistance::SurfaceDistance(SurfaceDistance&&) noexcept = default;
SurfaceDistance& SurfaceDistance::operator=(SurfaceDistance&&) noexcept = default;

double SurfaceDistance::bbox_diagonal_mm() const { return m_impl->bbox_diagonal; }

void SurfaceDistance::closest_points(const Positions& points, Positions& closest, Eigen::VectorXd* distances,
                                     Eigen::VectorXi* faces) const {
  const Impl& impl = *m_impl;
  closest.resize(points.rows(), 3);
  if (distances) distances->resize(points.rows());
  if (faces) faces->resize(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Point q(points(i, 0), points(i, 1), points(i, 2));
    const auto [c, primitive] = impl.tree.closest_point_and_primitive(q);
    closest.row(i) << c.x(), c.y(), c.z();
    if (distances) (*distances)(i) = std::sqrt(CGAL::squared_distance(q, c));
    if (faces) (*faces)(i) = impl.face_of_triangle[static_cast<size_t>(primitive - impl.triangles.cbegin())];
  }
}

Eigen::VectorXd SurfaceDistance::distances(const Positions& points) const {
  Eigen::VectorXd d(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    d(i) = std::sqrt(m_impl->tree.squared_distance(Point(points(i, 0), points(i, 1), points(i, 2))));
  }
  return d;
}

SurfaceDistanceStats SurfaceDistance::stats(const Positions& points) const {
  SurfaceDistanceStats s;
  s.bbox_diag_mm = m_impl->bbox_diagonal;
  if (points.rows() == 0) return s;
  const Eigen::VectorXd d = distances(points);
  s.avg_mm = d.mean();
  s.max_mm = d.maxCoeff();
  s.rms_mm = std::sqrt(d.squaredNorm() / static_cast<double>(d.size()));
  if (s.bbox_diag_mm > 0.0) {
    s.avg_rel = s.avg_mm / s.bbox_diag_mm;
    s.max_rel = s.max_mm / s.bbox_diag_mm;
  }
  return s;
}

SurfaceDistanceStats SurfaceDistance::aligned_stats(const Positions& points, const Positions& reference_points) const {
  return stats(rigid_align_to(points, reference_points));
}

Positions RigidTransform::apply(const Positions& points) const {
  Positions out(points.rows(), 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    out.row(i) = (rotation * points.row(i).transpose() + translation).transpose();
  }
  return out;
}

RigidTransform rigid_alignment(const Positions& points, const Positions& reference_points) {
  if (points.rows() != reference_points.rows() || points.rows() < 3) {
    throw std::invalid_argument("rigid_alignment: needs two point sets of equal size >= 3");
  }
  const Eigen::RowVector3d pc = points.colwise().mean(), qc = reference_points.colwise().mean();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    cov += (points.row(i) - pc).transpose() * (reference_points.row(i) - qc);
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  // Flip the weakest axis if the best orthogonal map is a reflection.
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (v * u.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  RigidTransform t;
  t.rotation = v * d * u.transpose();
  t.translation = qc.transpose() - t.rotation * pc.transpose();
  return t;
}

Positions rigid_align_to(const Positions& points, const Positions& reference_points) {
  return rigid_alignment(points, reference_points).apply(points);
}

}  // namespace balloon
