#pragma once
/// Mesh-wide sums of the membrane and pressure terms: the total potential W(x) - p V(x) of a balloon
/// with a fixed rest shape, its gradient, and its Hessian assembled through TriangleAssembly.
/// Positions are flat 3#V vectors in mm; pressure p in MPa inside core (kPa only at the user edge).
#include <Eigen/Core>
#include <vector>

#include "fem/assembly.hpp"
#include "fem/hinge_bending.hpp"
#include "fem/membrane_element.hpp"
#include "material/material.hpp"
#include "mesh/tri_mesh.hpp"

namespace balloon::fem {

class BalloonModel {
 public:
  /// `element_thickness` has one entry per triangle (mm).
  BalloonModel(const TriMesh& rest, const Material& material, std::vector<double> element_thickness);

  /// Switches Pipkin's tension-field relaxation on or off (off by default; see membrane_element.hpp).
  void set_tension_field(bool on) { m_tension_field = on; }
  bool tension_field() const { return m_tension_field; }

  /// Switches the sheet's bending stiffness on or off (off by default; see hinge_bending.hpp). An
  /// assembly for a model with bending needs its hinges: TriangleAssembly(faces(), vertex_count(), fixed,
  /// hinges()).
  void set_bending(bool on);
  bool bending() const { return m_bending; }
  /// The bending hinges (empty while bending is off).
  const std::vector<HingeVertices>& hinges() const { return m_hinges; }
  /// Rest data of hinge `hinge` (bending on).
  const RestHinge& rest_hinge(int hinge) const { return m_rest_hinges[static_cast<size_t>(hinge)]; }

  /// Replaces the rest positions (same connectivity); the design optimizer moves them.
  void set_rest_positions(const Positions& rest);

  const Faces& faces() const { return m_faces; }
  const Positions& rest_positions() const { return m_rest; }
  const Material& material() const { return m_material; }
  int vertex_count() const { return static_cast<int>(m_rest.rows()); }
  double rest_area() const { return m_rest_area; }
  double thickness(int face) const { return m_thickness[static_cast<size_t>(face)]; }

  /// Corner positions of triangle `face` as a 9-vector.
  Vector9d corners(const Eigen::VectorXd& x, int face) const;
  /// Positions of hinge `hinge`'s stencil as a 12-vector.
  Vector12d hinge_corners(const Eigen::VectorXd& x, int hinge) const;

  /// Elastic energy W (N*mm): membrane, plus bending when on; +infinity when a triangle has collapsed.
  double elastic_energy(const Eigen::VectorXd& x) const;
  /// dW/dx (3#V, N).
  Eigen::VectorXd elastic_gradient(const Eigen::VectorXd& x) const;
  /// Enclosed (signed) volume V (mm^3).
  double volume(const Eigen::VectorXd& x) const;
  /// dV/dx (3#V, mm^2): a third of the area-weighted normals at each vertex.
  Eigen::VectorXd volume_gradient(const Eigen::VectorXd& x) const;
  /// Surface area (mm^2).
  double area(const Eigen::VectorXd& x) const;
  /// Largest principal stretch over all triangles.
  double max_stretch(const Eigen::VectorXd& x) const;
  /// Triangles that are wrinkled or slack at x (some principal stress would be compressive); counted
  /// whether or not the tension field is on.
  int relaxed_triangle_count(const Eigen::VectorXd& x) const;

  /// Assembles the Hessian of W - p V (N/mm) into `assembly` (which is zeroed first).
  /// `project_membrane` clamps each membrane (and hinge) block to positive semi-definite.
  void assemble_hessian(const Eigen::VectorXd& x, double pressure_mpa, TriangleAssembly& assembly,
                        bool project_membrane) const;

 private:
  Faces m_faces;
  Positions m_rest;
  Material m_material;
  std::vector<double> m_thickness;
  std::vector<RestTriangle> m_rest_triangles;
  double m_rest_area = 0.0;
  bool m_tension_field = false;
  bool m_bending = false;
  std::vector<HingeVertices> m_hinges;
  std::vector<RestHinge> m_rest_hinges;
  std::vector<double> m_hinge_modulus;  ///< D of each hinge (N*mm), fixed with the thickness

  /// Rest data of the hinges from the current rest positions (bending on).
  void update_rest_hinges();
};

}  // namespace balloon::fem
