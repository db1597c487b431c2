#include "implicit_shapes.hpp"

#include <CGAL/Complex_2_in_triangulation_3.h>
#include <CGAL/IO/facets_in_complex_2_to_triangle_mesh.h>
#include <CGAL/Implicit_surface_3.h>
#include <CGAL/Random.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_default_triangulation_3.h>
#include <CGAL/make_surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>

#include "mesh/mesh_geometry.hpp"

namespace balloon::test_shapes {
namespace {

using Triangulation = CGAL::Surface_mesh_default_triangulation_3;
using Complex = CGAL::Complex_2_in_triangulation_3<Triangulation>;
using Kernel = Triangulation::Geom_traits;
using Point = Kernel::Point_3;
using FT = Kernel::FT;
using Field = std::function<double(const Eigen::Vector3d&)>;  ///< negative inside

/// Polynomial smooth minimum (a union with fillets of radius about k).
double smooth_min(double a, double b, double k) {
  const double h = std::clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
  return b + (a - b) * h - k * h * (1.0 - h);
}

double sphere(const Eigen::Vector3d& p, const Eigen::Vector3d& center, double radius) {
  return (p - center).norm() - radius;
}

double capsule(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm() - radius;
}

double torus(const Eigen::Vector3d& p, const Eigen::Vector3d& center, double major, double minor) {
  const Eigen::Vector3d q = p - center;
  const double ring = std::hypot(q.x(), q.y()) - major;
  return std::hypot(ring, q.z()) - minor;
}

struct Family {
  std::string name;
  std::string features;
  Field field;
};

/// The families, their parameters drawn from `random`.
std::vector<Family> families(std::mt19937& random) {
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
  std::vector<Family> out;
  {
    const double p = uniform(5.0, 8.0), b = uniform(0.6, 0.8), c = uniform(0.35, 0.5);
    out.push_back({"superellipsoid", "flat faces with rounded edges (exponent " + std::to_string(p) + ")",
                   [=](const Eigen::Vector3d& x) {
                     return std::pow(std::pow(std::abs(x.x()), p) + std::pow(std::abs(x.y() / b), p) +
                                         std::pow(std::abs(x.z() / c), p),
                                     1.0 / p) - 0.9;
                   }});
  }
  {
    const double p = uniform(10.0, 14.0), c = uniform(0.2, 0.3);
    out.push_back({"tablet", "a flat tablet with a sharp rim (exponent " + std::to_string(p) + ")",
                   [=](const Eigen::Vector3d& x) {
                     return std::pow(std::pow(std::abs(x.x()), p) + std::pow(std::abs(x.y()), p) +
                                         std::pow(std::abs(x.z() / c), p),
                                     1.0 / p) - 0.9;
                   }});
  }
  {
    // A sphere with Gaussian dents and bumps: concave regions beside convex ones.
    std::vector<std::pair<Eigen::Vector3d, double>> bumps;
    for (int i = 0; i < 7; ++i) {
      Eigen::Vector3d d(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      bumps.push_back({d.normalized(), (i % 2 ? 1.0 : -1.0) * uniform(0.15, 0.3)});
    }
    out.push_back({"dented_blob", "dents and bumps: concave and saddle regions",
                   [=](const Eigen::Vector3d& x) {
                     const double r = x.norm();
                     if (r < 1e-9) return -0.8;
                     const Eigen::Vector3d dir = x / r;
                     double radius = 0.8;
                     for (const auto& [center, amplitude] : bumps)
                       radius += amplitude * std::exp(-(dir - center).squaredNorm() / 0.15);
                     return r - radius;
                   }});
  }
  {
    const double minor = uniform(0.12, 0.2);
    out.push_back({"thin_torus", "genus 1 with a thin tube (tube radius " + std::to_string(minor) + " of ring 0.75)",
                   [=](const Eigen::Vector3d& x) { return torus(x, Eigen::Vector3d::Zero(), 0.75, minor); }});
  }
  {
    const double minor = uniform(0.18, 0.25), shift = uniform(0.45, 0.55);
    out.push_back({"double_torus", "genus 2: two fused rings",
                   [=](const Eigen::Vector3d& x) {
                     return smooth_min(torus(x, Eigen::Vector3d(-shift, 0, 0), 0.45, minor),
                                       torus(x, Eigen::Vector3d(shift, 0, 0), 0.45, minor), 0.05);
                   }});
  }
  {
    const double neck = uniform(0.1, 0.16), ball = uniform(0.4, 0.5);
    out.push_back({"dumbbell", "two balls on a thin neck (neck radius " + std::to_string(neck) + ")",
                   [=](const Eigen::Vector3d& x) {
                     const double balls = std::min(sphere(x, Eigen::Vector3d(-0.5, 0, 0), ball),
                                                   sphere(x, Eigen::Vector3d(0.5, 0, 0), ball));
                     return smooth_min(balls, capsule(x, Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(0.5, 0, 0), neck),
                                       0.08);
                   }});
  }
  {
    const double arm = uniform(0.08, 0.12), core = uniform(0.25, 0.32);
    out.push_back({"jack", "six thin limbs from a small core (limb radius " + std::to_string(arm) + ")",
                   [=](const Eigen::Vector3d& x) {
                     double d = sphere(x, Eigen::Vector3d::Zero(), core);
                     for (int axis = 0; axis < 3; ++axis) {
                       Eigen::Vector3d end = Eigen::Vector3d::Zero();
                       end[axis] = 0.85;
                       d = smooth_min(d, capsule(x, -end, end, arm), 0.06);
                     }
                     return d;
                   }});
  }
  {
    // A palm with four fingers of different lengths and a thumb: limbs side by side, narrow gaps.
    std::vector<double> lengths;
    for (int i = 0; i < 5; ++i) lengths.push_back(uniform(0.35, 0.6));
    const double finger = uniform(0.07, 0.1);
    out.push_back({"mitten", "a palm with five thin fingers and narrow gaps between them",
                   [=](const Eigen::Vector3d& x) {
                     const Eigen::Vector3d q(x.x(), x.y(), x.z() / 0.45);
                     double d = (q.norm() - 0.4) * 0.45;  // a flattened palm
                     for (int i = 0; i < 4; ++i) {
                       const Eigen::Vector3d base(-0.27 + 0.18 * i, 0.25, 0);
                       d = smooth_min(d, capsule(x, base, base + Eigen::Vector3d(0, lengths[i], 0), finger), 0.04);
                     }
                     const Eigen::Vector3d thumb(-0.3, -0.05, 0);
                     const Eigen::Vector3d thumb_tip = thumb + lengths[4] * Eigen::Vector3d(-0.8, 0.6, 0);
                     d = smooth_min(d, capsule(x, thumb, thumb_tip, finger), 0.04);
                     return d;
                   }});
  }
  return out;
}

/// Meshes `field` (negative inside, within a sphere of radius 1.6 about the origin) with triangles of
/// about `size`, as a closed manifold with outward triangles; false when the mesher finds no surface.
bool mesh_field(const Field& field, double size, TriMesh& out) {
  // The mesher draws its initial points from CGAL's default generator, which is seeded from the clock:
  // seeded here, the same shape meshes the same way every run.
  CGAL::get_default_random() = CGAL::Random(1);
  Triangulation triangulation;
  Complex complex(triangulation);
  auto function = [&](const Point& p) -> FT { return field(Eigen::Vector3d(p.x(), p.y(), p.z())); };
  using Surface = CGAL::Implicit_surface_3<Kernel, std::function<FT(const Point&)>>;
  Surface surface(std::function<FT(const Point&)>(function), Kernel::Sphere_3(Point(0, 0, 0), 1.6 * 1.6), 1e-6);
  CGAL::Surface_mesh_default_criteria_3<Triangulation> criteria(25.0, size, 0.1 * size);
  CGAL::make_surface_mesh(complex, surface, criteria, CGAL::Manifold_tag());
  CGAL::Surface_mesh<Point> mesh;
  CGAL::facets_in_complex_2_to_triangle_mesh(complex, mesh);
  if (mesh.number_of_faces() == 0) return false;
  out.vertices.resize(static_cast<Eigen::Index>(mesh.number_of_vertices()), 3);
  for (auto v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    out.vertices.row(static_cast<Eigen::Index>(v)) << p.x(), p.y(), p.z();
  }
  out.faces.resize(static_cast<Eigen::Index>(mesh.number_of_faces()), 3);
  for (auto f : mesh.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      out.faces(static_cast<Eigen::Index>(f), k++) = static_cast<int>(v);
  }
  // Outward triangles: a negative enclosed volume means the mesher wound them inwards.
  if (enclosed_volume(out.vertices, out.faces) < 0.0) out.faces.col(1).swap(out.faces.col(2));
  return true;
}

}  // namespace

std::vector<ImplicitShape> implicit_shapes(unsigned seed, double size) {
  std::mt19937 random(seed);
  std::vector<ImplicitShape> shapes;
  for (const Family& family : families(random)) {
    ImplicitShape shape{family.name + "_" + std::to_string(seed), family.features, {}};
    if (mesh_field(family.field, size, shape.mesh)) shapes.push_back(std::move(shape));
  }
  return shapes;
}

}  // namespace balloon::test_shapes
