#pragma once
/// Closed-form nominal stresses of an incompressible rubber in the homogeneous laboratory tests
/// (uniaxial, equibiaxial, pure shear) and the thin-sphere balloon law. These are the model curves the
/// material fits compare against published stress-stretch tables.
#include "material/material.hpp"

namespace balloon {

/// A homogeneous deformation of an incompressible solid, by its principal stretches (l = loading stretch):
///  - Uniaxial:    (l, l^-1/2, l^-1/2)
///  - Equibiaxial: (l, l, l^-2)
///  - PureShear:   (l, 1, l^-1)   (planar tension)
enum class Deformation { Uniaxial, Equibiaxial, PureShear };

/// The invariants I1 = sum l_i^2 and I2 = sum l_i^-2 (incompressible) of a homogeneous deformation.
struct DeformationInvariants {
  double I1 = 3.0, I2 = 3.0;
};

/// Invariants of `deformation` at loading stretch `stretch` (> 0, dimensionless).
DeformationInvariants deformation_invariants(Deformation deformation, double stretch);

/// Strain energy per rest volume W(l) = Psi(I1(l), I2(l)) (MPa = N*mm/mm^3) at loading stretch `stretch`.
double strain_energy_density(const Material& material, Deformation deformation, double stretch);

/// Nominal (first Piola-Kirchhoff, force per rest area) stress in the loading direction (MPa), with
/// Psi1 = dPsi/dI1 and Psi2 = dPsi/dI2 from strain_energy():
///  - Uniaxial:    P = dW/dl       = 2 (l - l^-2) (Psi1 + Psi2 / l)
///  - Equibiaxial: P = (1/2) dW/dl = 2 (l - l^-5) (Psi1 + l^2 Psi2)   (two loaded directions share dW)
///  - PureShear:   P = dW/dl       = 2 (l - l^-3) (Psi1 + Psi2)
double nominal_stress(const Material& material, Deformation deformation, double stretch);

/// Inflation pressure (MPa) of a thin sphere of rest radius `rest_radius_mm` and rest wall thickness
/// `rest_thickness_mm` at stretch `stretch` = r / R: p = (2 H / R) P_ET(l) / l^2 (membrane theory,
/// Laplace's law with the thinned wall H / l^2). Equivalently p = H W_ET'(l) / (R l^2) by virtual work.
double sphere_pressure(const Material& material, double rest_radius_mm, double rest_thickness_mm, double stretch);

}  // namespace balloon
