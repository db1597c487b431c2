// One of the files that include CGAL (isotropic remeshing).
#include "design/target_preparation.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mesh/self_intersection.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), fmt, value);
  return buffer;
}

SurfaceMesh to_surface_mesh(const TriMesh& mesh) {
  SurfaceMesh out;
  out.reserve(static_cast<SurfaceMesh::size_type>(mesh.vertex_count()),
              static_cast<SurfaceMesh::size_type>(3 * mesh.face_count() / 2),
              static_cast<SurfaceMesh::size_type>(mesh.face_count()));
  std::vector<SurfaceMesh::Vertex_index> handles;
  handles.reserve(static_cast<size_t>(mesh.vertex_count()));
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    handles.push_back(out.add_vertex(Kernel::Point_3(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2))));
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    const auto face = out.add_face(handles[static_cast<size_t>(mesh.faces(f, 0))],
                                   handles[static_cast<size_t>(mesh.faces(f, 1))],
                                   handles[static_cast<size_t>(mesh.faces(f, 2))]);
    // validate_balloon_mesh ran first: a closed oriented manifold always adds.
    if (face == SurfaceMesh::null_face()) throw std::logic_error("to_surface_mesh: face " + std::to_string(f) + " rejected");
  }
  return out;
}

TriMesh to_tri_mesh(SurfaceMesh& mesh) {
  mesh.collect_garbage();  // indices become 0..n-1 in order
  TriMesh out;
  out.vertices.resize(static_cast<Eigen::Index>(mesh.number_of_vertices()), 3);
  for (const auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    out.vertices.row(static_cast<Eigen::Index>(v.idx())) << p.x(), p.y(), p.z();
  }
  out.faces.resize(static_cast<Eigen::Index>(mesh.number_of_faces()), 3);
  for (const auto f : mesh.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
      out.faces(static_cast<Eigen::Index>(f.idx()), k++) = static_cast<int>(v.idx());
    }
  }
  return out;
}

TriMesh remesh(const TriMesh& mesh, double edge_length, int iterations) {
  SurfaceMesh sm = to_surface_mesh(mesh);
  PMP::isotropic_remeshing(CGAL::faces(sm), edge_length, sm,
                           CGAL::parameters::number_of_iterations(static_cast<unsigned>(iterations)));
  return to_tri_mesh(sm);
}

}  // namespace

Result<PreparedTarget> prepare_target(TriMesh target, const TargetPreparationOptions& options) {
  if (!std::isfinite(options.size_mm) || options.size_mm < 0.0) {
    return fail("size must be a finite length >= 0 mm (0 keeps the size), got " + format("%g", options.size_mm));
  }
  if (options.resolution < 0 || (options.resolution > 0 && options.resolution < 100)) {
    return fail("resolution must be 0 (never remesh) or at least 100 vertices, got " +
                std::to_string(options.resolution));
  }
  if (options.remesh_iterations < 1) return fail("remesh_iterations must be >= 1");

  PreparedTarget out;
  auto checked = validate_balloon_mesh(target);
  if (!checked) return fail("target mesh: " + checked.error());
  out.reoriented = checked->flipped;
  out.unreferenced_vertices_removed = checked->removed_unreferenced_vertices;
  for (const std::string& note : checked->notes) out.summary += note + "\n";

  const double diagonal = bounding_box_diagonal(target.vertices);
  if (options.size_mm > 0.0) {
    out.scale_factor = scale_to_diagonal(target.vertices, options.size_mm);
    out.summary += "scaled by " + format("%.6g", out.scale_factor) + " (bounding-box diagonal " +
                   format("%.6g", diagonal) + " -> " + format("%.6g", options.size_mm) + " mm)\n";
  }

  out.vertices_before = target.vertex_count();
  out.faces_before = target.face_count();
  out.min_angle_before_deg = min_angle_deg(target.vertices, target.faces);
  const int wanted = options.resolution;
  const bool count_ok =
      wanted == 0 || std::abs(out.vertices_before - wanted) <= options.keep_vertex_tolerance * wanted;
  const bool quality_ok = out.min_angle_before_deg > options.keep_min_angle_deg;
  if (wanted > 0 && !(count_ok && quality_ok)) {
    // Closed mesh: F ~ 2V equilateral triangles of area sqrt(3)/4 L^2 cover the area A.
    const double area = surface_area(target.vertices, target.faces);
    double length = std::sqrt(2.0 * area / (std::sqrt(3.0) * wanted));
    TriMesh remeshed = remesh(target, length, options.remesh_iterations);
    // The count lands within a few tens of percent of N (splits at 4/3 L, collapses at 4/5 L);
    // one pass with L corrected by sqrt(V / N) brings it closer.
    const double miss = static_cast<double>(remeshed.vertex_count()) / wanted;
    if (std::abs(miss - 1.0) > 0.1) {
      length *= std::sqrt(miss);
      remeshed = remesh(target, length, options.remesh_iterations);
    }
    auto remesh_check = validate_balloon_mesh(remeshed);
    if (!remesh_check) {
      return fail("remeshing the target to " + std::to_string(wanted) + " vertices broke it (" +
                  remesh_check.error() + "); try another resolution or --resolution 0");
    }
    if (remesh_check->flipped) return fail("remeshing the target turned it inside out");
    out.remeshed = true;
    out.target_edge_length_mm = length;
    target = std::move(remeshed);
  }
  out.vertices_after = target.vertex_count();
  out.faces_after = target.face_count();
  out.min_angle_after_deg = min_angle_deg(target.vertices, target.faces);
  if (out.remeshed) {
    out.summary += "remeshed from " + std::to_string(out.vertices_before) + " to " +
                   std::to_string(out.vertices_after) + " vertices (edge length " +
                   format("%.4g", out.target_edge_length_mm) + " mm, min angle " +
                   format("%.1f", out.min_angle_before_deg) + " -> " + format("%.1f", out.min_angle_after_deg) +
                   " deg)\n";
  } else if (wanted > 0) {
    out.summary += "kept the mesh as it is (" + std::to_string(out.vertices_before) + " vertices, min angle " +
                   format("%.1f", out.min_angle_before_deg) + " deg)\n";
  } else {
    out.summary += "remeshing disabled (resolution 0)\n";
  }
  {
    out.self_intersecting = mesh_self_intersects(target);
    if (out.self_intersecting) out.summary += "warning: the prepared target has self-intersecting triangles\n";
  }
  out.bbox_diag_mm = bounding_box_diagonal(target.vertices);
  out.area_mm2 = surface_area(target.vertices, target.faces);
  out.volume_mm3 = enclosed_volume(target.vertices, target.faces);
  out.mesh = std::move(target);
  if (!out.summary.empty() && out.summary.back() == '\n') out.summary.pop_back();
  return out;
}

}  // namespace balloon
