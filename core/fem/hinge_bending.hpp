#pragma once
/// The sheet's real bending stiffness, as discrete-shell hinges (Grinspun et al., "Discrete Shells",
/// SCA 2003). A membrane alone has no stiffness against folding, so a compressed region has no stable
/// state and Newton creeps through ever finer wrinkles; a rubber sheet of thickness h does resist
/// bending, with D = E h^3 / (12 (1 - nu^2)) = G h^3 / 3 for an incompressible sheet (E = 3G, nu = 1/2).
///
/// Each interior edge e carries E_e = k (theta - theta_rest)^2, theta the dihedral angle between the
/// normals of its two triangles, k = (3 D / 4) |e|^2 / (A_a + A_b) from the rest edge and areas (the
/// bending energy D/2 kappa^2 of a strip of width (h_a + h_b)/3 bent by theta). Dihedral angles do not
/// change under a uniform scaling, so a sphere inflates as without bending.
///
/// Stencil: x is a 12-vector (x0, x1, x2, x3) in mm; the edge runs x0 -> x1 in the first triangle
/// (x0, x1, x2), whose neighbour across it is (x1, x0, x3). Energies in N*mm, gradients in N.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "mesh/tri_mesh.hpp"

namespace balloon::fem {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// The four vertices of one interior edge's hinge, in stencil order (see above).
using HingeVertices = std::array<int, 4>;

/// Every edge shared by exactly two triangles of a consistently oriented mesh, as a hinge. With
/// `hinge_faces`, also the two triangles of each (the one with x0 -> x1 first).
std::vector<HingeVertices> mesh_hinges(const Faces& faces, std::vector<std::array<int, 2>>* hinge_faces = nullptr);

/// Rest-state data of one hinge.
struct RestHinge {
  double stiffness = 0.0;   ///< k (N*mm per rad^2)
  double rest_angle = 0.0;  ///< theta_rest (rad)
  double modulus = 0.0;     ///< the sheet's bending modulus D (N*mm) it was made with
};

/// Rest data from the rest stencil and the sheet's bending modulus D (N*mm).
RestHinge make_rest_hinge(const Vector12d& rest, double bending_modulus);

/// Bending modulus D = G h^3 / 3 (N*mm) of an incompressible sheet of small-strain shear modulus G (MPa)
/// and thickness h (mm).
double bending_modulus(double shear_modulus_mpa, double thickness_mm);

/// Signed dihedral angle (rad) between the normals of the two triangles: 0 when flat, positive when the
/// hinge folds outwards (convex, as on a sphere).
double dihedral_angle(const Vector12d& x);

/// Hinge energy k (theta - theta_rest)^2 (N*mm).
double hinge_energy(const RestHinge& rest, const Vector12d& x);

/// Gradient of the hinge energy (12, N).
Vector12d hinge_energy_gradient(const RestHinge& rest, const Vector12d& x);

/// Energy, gradient (N) and Hessian (N/mm) in one pass. With `project_to_psd` the Hessian is its
/// Gauss-Newton part 2 k grad(theta) grad(theta)^T, positive semi-definite; otherwise exact.
void hinge_energy_gradient_hessian(const RestHinge& rest, const Vector12d& x, double& energy, Vector12d& gradient,
                                   Matrix12d& hessian, bool project_to_psd = false);

/// Mixed derivative d(gradient_x)/d(rest) (12x12, N/mm) of the hinge energy: row i a deformed
/// coordinate, column j a rest coordinate (both theta_rest and k move with the rest shape).
Matrix12d hinge_mixed_derivative(const RestHinge& rest_hinge, const Vector12d& rest, const Vector12d& x);

}  // namespace balloon::fem
