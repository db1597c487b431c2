#pragma once
/// A triangle mesh: positions in mm and counter-clockwise (outward) triangles.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products everywhere a mesh is used

namespace balloon {

/// #V by 3 vertex positions (mm), row-major so that the flat 3#V vector maps onto it without a copy.
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #F by 3 vertex indices per triangle, counter-clockwise seen from outside.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriMesh {
  Positions vertices;
  Faces faces;

  int vertex_count() const { return static_cast<int>(vertices.rows()); }
  int face_count() const { return static_cast<int>(faces.rows()); }
};

/// Flat view (x0,y0,z0,x1,...) of a position matrix.
inline Eigen::Map<Eigen::VectorXd> flat(Positions& p) { return {p.data(), p.size()}; }
inline Eigen::Map<const Eigen::VectorXd> flat(const Positions& p) { return {p.data(), p.size()}; }
/// Positions from a flat 3#V vector.
inline Positions unflatten(const Eigen::VectorXd& x) {
  return Eigen::Map<const Positions>(x.data(), x.size() / 3, 3);
}

}  // namespace balloon
