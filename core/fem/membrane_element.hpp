#pragma once
/// The incompressible membrane triangle of the paper (sec. 3.2, eq. 3 and 7-11): constant strain, the
/// 3x3 Cauchy-Green tensor diag-extended with 1/det C in the thickness slot, energy h * A_rest * Psi.
///
/// Everything is written through the edge Gram matrices of the deformed triangle,
/// S = [e12.e12, e12.e13; ., e13.e13], and of the rest triangle, M (same with rest edges): the in-plane
/// Cauchy-Green tensor has tr C = tr(S M^-1) and det C = det S / det M, and A_rest = sqrt(det M) / 2.
/// This equals the paper's frame construction (eq. 7-10) without building frames.
///
/// Tension field (`tension_field` = true): Pipkin's relaxed energy, the membrane's answer to compression.
/// A thin sheet cannot carry compressive stress; it wrinkles at a scale below the mesh instead. With
/// principal stretches l1 >= l2 (l3 = 1/(l1 l2)), a triangle is
///  - taut when l1 l2^2 >= 1 (both principal stresses >= 0): the energy above, unchanged;
///  - wrinkled when l1 l2^2 < 1 < l1: the energy of uniaxial tension at l1 (l2 replaced by its natural
///    width l1^-1/2, where the lateral stress vanishes), carrying tension along l1 only;
///  - slack when l1 <= 1: no energy.
/// The energy stays C1 across the three; its Hessian is kept positive semi-definite in relaxed triangles.
///
/// Stencils: x and rest are 9-vectors (x1, y1, z1, x2, ..., z3) in mm; energies in N*mm, gradients in N.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "material/material.hpp"

namespace balloon::fem {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;

/// Rest-state data of one triangle, computed once per rest shape.
struct RestTriangle {
  double m11 = 0, m12 = 0, m22 = 0;  ///< rest edge Gram matrix entries (mm^2)
  double area = 0;                   ///< rest area (mm^2)
};

/// Rest data from the rest positions of the three corners.
RestTriangle make_rest_triangle(const Vector9d& rest);

/// Membrane energy W = h * A_rest * Psi(I1, I2) (N*mm). Infinite for a collapsed deformed triangle.
double membrane_energy(const Material& material, double thickness, const RestTriangle& rest, const Vector9d& x,
                       bool tension_field = false);

/// Gradient of the energy with respect to the deformed positions (9, N); the elastic force is its negative.
Vector9d membrane_gradient(const Material& material, double thickness, const RestTriangle& rest, const Vector9d& x,
                           bool tension_field = false);

/// Energy, gradient and Hessian (9x9, N/mm) with respect to the deformed positions in one pass.
/// With `project_to_psd`, the two parts of the Hessian (material curvature and geometric stress) are
/// each clamped to be positive semi-definite, so the sum is too; otherwise it is exact (except in
/// relaxed triangles under `tension_field`, which are always clamped; see above).
void membrane_energy_gradient_hessian(const Material& material, double thickness, const RestTriangle& rest,
                                      const Vector9d& x, double& energy, Vector9d& gradient, Matrix9d& hessian,
                                      bool project_to_psd = false, bool tension_field = false);

/// Mixed derivative d(gradient_x)/d(rest) (9x9, N/mm): row i is a deformed coordinate, column j a rest
/// coordinate. The element forces are minus the gradient, so d(force)/d(rest) is minus this.
Matrix9d membrane_mixed_derivative(const Material& material, double thickness, const Vector9d& rest,
                                   const Vector9d& x, bool tension_field = false);

/// True when the tension field relaxes the triangle (wrinkled or slack: some principal stress would be
/// compressive).
bool is_relaxed(const RestTriangle& rest, const Vector9d& x);

/// Squares of the principal in-plane stretches (eigenvalues of C), ascending.
Eigen::Vector2d principal_stretches_squared(const RestTriangle& rest, const Vector9d& x);

}  // namespace balloon::fem
