// Where a design's remaining error sits (issue 10, section 2): per region of the target's curvature, and
// in the triangles the inflated balloon compresses. A pressurised membrane carries only tension, so
// sigma_1 k_1 + sigma_2 k_2 = p > 0 cannot hold where both principal curvatures are negative (a dent): there
// the error is a physical floor. Elsewhere it is what the optimizer left.
// Usage: design_error_by_region TARGET_MESH DESIGN_DIR [--size MM=150] [--resolution N=4000]
//   DESIGN_DIR as written by `balloon design --out-dir` (inflated.obj and rest.obj on the prepared
//   target's connectivity); --size and --resolution as given to that design.
// Prints, per region (convex, saddle, concave, flat): its share of the target's area, its share of the
// area-weighted error, its mean error (mm) and how much of it lies outside the target; then the same for
// the vertices of compressed triangles (Neo-Hookean sign: the smaller principal stress is negative).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "design/surface_distance.hpp"
#include "design/target_preparation.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"

namespace {

using balloon::Positions;
using balloon::TriMesh;

enum Region { Convex, Saddle, Concave, Flat, REGION_COUNT };
const char* const REGION_NAMES[REGION_COUNT] = {"convex", "saddle", "concave", "flat"};

/// Per vertex: barycentric area (mm^2), outward normal, and the principal curvatures (1/mm, positive
/// where the surface bends away from its outward normal) from the angle defect and the cotangent
/// Laplacian.
struct VertexCurvature {
  Eigen::VectorXd area, k_max, k_min;
  Positions normal;
};

VertexCurvature vertex_curvature(const TriMesh& mesh) {
  const int n = mesh.vertex_count();
  const Positions& x = mesh.vertices;
  Eigen::VectorXd defect = Eigen::VectorXd::Constant(n, 2.0 * M_PI);
  VertexCurvature out{Eigen::VectorXd::Zero(n), Eigen::VectorXd(n), Eigen::VectorXd(n), Positions::Zero(n, 3)};
  Positions laplacian = Positions::Zero(n, 3);
  for (int f = 0; f < mesh.face_count(); ++f) {
    const std::array<int, 3> v = {mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
    const Eigen::RowVector3d area_normal = (x.row(v[1]) - x.row(v[0])).cross(x.row(v[2]) - x.row(v[0]));
    for (int k = 0; k < 3; ++k) {
      const int i = v[k], j = v[(k + 1) % 3], l = v[(k + 2) % 3];
      const Eigen::Vector3d a = (x.row(j) - x.row(i)).transpose(), b = (x.row(l) - x.row(i)).transpose();
      defect[i] -= std::atan2(a.cross(b).norm(), a.dot(b));
      out.area[i] += area_normal.norm() / 6.0;
      out.normal.row(i) += area_normal;
      const double cot = a.dot(b) / a.cross(b).norm();  // the angle at i weighs the opposite edge (j, l)
      laplacian.row(j) += 0.5 * cot * (x.row(l) - x.row(j));
      laplacian.row(l) += 0.5 * cot * (x.row(j) - x.row(l));
    }
  }
  for (int i = 0; i < n; ++i) {
    out.normal.row(i).normalize();
    const double gaussian = defect[i] / out.area[i];
    const double mean = -0.5 * laplacian.row(i).dot(out.normal.row(i)) / out.area[i];
    const double spread = std::sqrt(std::max(0.0, mean * mean - gaussian));
    out.k_max[i] = mean + spread;
    out.k_min[i] = mean - spread;
  }
  return out;
}

/// Per vertex: whether a triangle around it is compressed, i.e. its smaller principal stress is negative for a
/// Neo-Hookean sheet (lambda_2 < lambda_1^-1/2).
std::vector<bool> compressed_vertices(const TriMesh& rest, const Positions& inflated) {
  std::vector<bool> touched(static_cast<size_t>(rest.vertex_count()), false);
  for (int f = 0; f < rest.face_count(); ++f) {
    const int i = rest.faces(f, 0), j = rest.faces(f, 1), l = rest.faces(f, 2);
    const Eigen::Vector3d a = (rest.vertices.row(j) - rest.vertices.row(i)).transpose();
    const Eigen::Vector3d b = (rest.vertices.row(l) - rest.vertices.row(i)).transpose();
    const Eigen::Vector3d da = (inflated.row(j) - inflated.row(i)).transpose();
    const Eigen::Vector3d db = (inflated.row(l) - inflated.row(i)).transpose();
    Eigen::Matrix2d rest_metric, inflated_metric;
    rest_metric << a.dot(a), a.dot(b), a.dot(b), b.dot(b);
    inflated_metric << da.dot(da), da.dot(db), da.dot(db), db.dot(db);
    const Eigen::Matrix2d cauchy_green = rest_metric.inverse() * inflated_metric;
    const double trace = cauchy_green.trace(), det = cauchy_green.determinant();
    const double larger = 0.5 * (trace + std::sqrt(std::max(0.0, trace * trace - 4.0 * det)));  // lambda_1^2
    const double smaller = det / larger;                                                          // lambda_2^2
    if (smaller * smaller * larger < 1.0)
      for (int k = 0; k < 3; ++k) touched[static_cast<size_t>(rest.faces(f, k))] = true;
  }
  return touched;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: design_error_by_region TARGET_MESH DESIGN_DIR [--size MM=150] [--resolution N=4000]\n");
    return 2;
  }
  balloon::TargetPreparationOptions preparation;
  preparation.size_mm = 150.0;
  for (int a = 3; a < argc; a += 2) {
    const std::string flag = argv[a];
    if (a + 1 < argc && flag == "--size") {
      preparation.size_mm = std::atof(argv[a + 1]);
    } else if (a + 1 < argc && flag == "--resolution") {
      preparation.resolution = std::atoi(argv[a + 1]);
    } else {
      std::fprintf(stderr, "unknown or incomplete option: %s\n", flag.c_str());
      return 2;
    }
  }
  const auto raw = balloon::read_mesh(argv[1]);
  const std::string dir = argv[2];
  const auto inflated = balloon::read_mesh(dir + "/inflated.obj");
  const auto rest = balloon::read_mesh(dir + "/rest.obj");
  if (!raw || !inflated || !rest) {
    std::fprintf(stderr, "cannot read the target or %s/{inflated,rest}.obj\n", dir.c_str());
    return 1;
  }
  const auto prepared = balloon::prepare_target(*raw, preparation);
  if (!prepared || prepared->mesh.vertex_count() != inflated->vertex_count()) {
    std::fprintf(stderr,
                 "the prepared target does not match the design's connectivity (other --size or --resolution?)\n");
    return 1;
  }
  const TriMesh& target = prepared->mesh;
  // The error the design reports: inflated vertices placed rigidly on the target, distance to its surface.
  const Positions placed = balloon::rigid_align_to(inflated->vertices, target.vertices);
  Positions closest;
  Eigen::VectorXd distance;
  balloon::SurfaceDistance(target).closest_points(placed, closest, &distance);
  const VertexCurvature curvature = vertex_curvature(target);
  const std::vector<bool> compressed = compressed_vertices(*rest, inflated->vertices);
  const double flat = 0.1 / balloon::bounding_box_diagonal(target.vertices);  // 1/mm: radius over 10 diagonals

  std::array<double, REGION_COUNT> area{}, error{}, outward{};
  double total_area = 0.0, total_error = 0.0, compressed_area = 0.0, compressed_error = 0.0;
  for (int v = 0; v < target.vertex_count(); ++v) {
    const double k_max = curvature.k_max[v], k_min = curvature.k_min[v];
    const Region region = std::max(std::abs(k_max), std::abs(k_min)) < flat ? Flat
                          : k_min > 0.0                                     ? Convex
                          : k_max < 0.0                                     ? Concave
                                                                            : Saddle;
    const double weight = curvature.area[v], weighted = distance[v] * weight;
    area[region] += weight;
    error[region] += weighted;
    if ((placed.row(v) - closest.row(v)).dot(curvature.normal.row(v)) > 0.0) outward[region] += weighted;
    total_area += weight;
    total_error += weighted;
    if (compressed[static_cast<size_t>(v)]) {
      compressed_area += weight;
      compressed_error += weighted;
    }
  }
  std::printf("%s: %d vertices, mean error %.3f mm (area-weighted %.3f mm)\n", argv[1], target.vertex_count(),
              distance.mean(), total_error / total_area);
  std::printf("%-10s %8s %12s %14s %10s\n", "region", "area", "error share", "mean error mm", "outward");
  for (int r = 0; r < REGION_COUNT; ++r)
    std::printf("%-10s %7.1f%% %11.1f%% %14.3f %9.1f%%\n", REGION_NAMES[r], 100.0 * area[r] / total_area,
                100.0 * error[r] / total_error, area[r] > 0.0 ? error[r] / area[r] : 0.0,
                error[r] > 0.0 ? 100.0 * outward[r] / error[r] : 0.0);
  std::printf("%-10s %7.1f%% %11.1f%% %14.3f\n", "compressed", 100.0 * compressed_area / total_area,
              100.0 * compressed_error / total_error, compressed_area > 0.0 ? compressed_error / compressed_area : 0.0);
  return 0;
}
