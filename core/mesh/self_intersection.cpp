// Includes CGAL (the only file of core/mesh that does): keep this file this small.
#include "mesh/self_intersection.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace balloon {

bool mesh_self_intersects(const TriMesh& mesh) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> handles;
  handles.reserve(static_cast<size_t>(mesh.vertex_count()));
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    handles.push_back(sm.add_vertex(Kernel::Point_3(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2))));
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.faces(f, k) < 0 || mesh.faces(f, k) >= mesh.vertex_count()) {
        throw std::invalid_argument("mesh_self_intersects: face " + std::to_string(f) + " has a bad index");
      }
    }
    const auto face = sm.add_face(handles[static_cast<size_t>(mesh.faces(f, 0))], handles[static_cast<size_t>(mesh.faces(f, 1))],
                                  handles[static_cast<size_t>(mesh.faces(f, 2))]);
    if (face == SurfaceMesh::null_face()) {
      throw std::invalid_argument("mesh_self_intersects: face " + std::to_string(f) + " is not manifold");
    }
  }
  return CGAL::Polygon_mesh_processing::does_self_intersect(sm);
}

}  // namespace balloon
