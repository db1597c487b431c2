#pragma once
/// Mesh-wide measures (volume, area, size, quality) and the edge list with its adjacent faces.
#include <Eigen/Core>

#include <array>

#include "mesh/tri_mesh.hpp"

namespace balloon {

/// Signed volume (mm^3) enclosed by the triangles F (#F x 3) over positions V (#V x 3, mm), by the
/// divergence theorem: sum over faces of a . (b x c) / 6, with a, b, c taken from the first vertex (the
/// products stay at the mesh's size wherever it stands). Positive for a closed mesh oriented outwards;
/// for an open mesh it depends on that reference point.
double enclosed_volume(const Positions& vertices, const Faces& faces);

/// Area (mm^2) of one triangle, face[0..2], over positions V (#V x 3, mm).
double triangle_area(const Positions& vertices, const Eigen::Vector3i& face);

/// Total area (mm^2) of the triangles F (#F x 3) over positions V (#V x 3, mm).
double surface_area(const Positions& vertices, const Faces& faces);

/// Length (mm) of the diagonal of the axis-aligned bounding box of all rows of V (#V x 3); 0 if empty.
double bounding_box_diagonal(const Positions& vertices);

/// Scales V about the origin so that its bounding-box diagonal is `diagonal_mm` (mm), as `--size` asks;
/// returns the factor, or 0 (V unchanged) when V has no finite, positive extent to scale.
double scale_to_diagonal(Positions& vertices, double diagonal_mm);

/// Mean of the rows of V (#V x 3, mm); a cheap centre for meshes with roughly uniform sampling.
Eigen::RowVector3d centroid(const Positions& vertices);

/// Interior angles (degrees) at the corners face[0], face[1], face[2] of one triangle over positions V
/// (#V x 3, mm); accurate down to the tiny angles of slivers.
std::array<double, 3> corner_angles_deg(const Positions& vertices, const Eigen::Vector3i& face);

/// Smallest interior angle (degrees) over all triangles F (#F x 3); 180 if F is empty.
double min_angle_deg(const Positions& vertices, const Faces& faces);

/// The undirected edges of a triangle mesh with their (at most two) faces.
struct EdgeTopology {
  /// #E x 2 vertex indices (a, b), in the direction face edge_faces(e, 0) traverses the edge; edges are
  /// sorted by (min(a, b), max(a, b)).
  Eigen::MatrixX2i edges;
  /// #E x 2 adjacent faces: column 0 traverses the edge as a -> b, column 1 is the other face
  /// (which traverses b -> a on a consistently oriented mesh), -1 on a boundary edge.
  Eigen::MatrixX2i edge_faces;
  /// #E x 2 vertex of face edge_faces(e, k) that is not on the edge, -1 where the face is -1.
  Eigen::MatrixX2i edge_opposite;
  /// #F x 3 index of the edge opposite corner k of face f (the edge (f[k+1], f[k+2])).
  Eigen::MatrixX3i face_edges;
};

/// Edges of the triangles F (#F x 3) over vertex_count vertices, O(F log F). Throws
/// std::invalid_argument if an index is out of range or an edge has more than two faces (validate the
/// mesh first: see validate_balloon_mesh).
EdgeTopology build_edge_topology(const Faces& faces, int vertex_count);

}  // namespace balloon
