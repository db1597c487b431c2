#include "material/homogeneous_tests.hpp"

#include <cmath>
#include <stdexcept>

namespace balloon {

DeformationInvariants deformation_invariants(Deformation deformation, double stretch) {
  if (!(stretch > 0.0)) throw std::invalid_argument("deformation_invariants: stretch must be positive");
  const double l = stretch, l2 = l * l;
  switch (deformation) {
    case Deformation::Uniaxial: return {l2 + 2.0 / l, 2.0 * l + 1.0 / l2};
    case Deformation::Equibiaxial: return {2.0 * l2 + 1.0 / (l2 * l2), l2 * l2 + 2.0 / l2};
    case Deformation::PureShear: return {l2 + 1.0 + 1.0 / l2, l2 + 1.0 + 1.0 / l2};
  }
  throw std::logic_error("deformation_invariants: unknown deformation");
}

double strain_energy_density(const Material& material, Deformation deformation, double stretch) {
  const auto inv = deformation_invariants(deformation, stretch);
  return strain_energy(material, inv.I1, inv.I2).psi;
}

double nominal_stress(const Material& material, Deformation deformation, double stretch) {
  const auto inv = deformation_invariants(deformation, stretch);
  const auto d = strain_energy(material, inv.I1, inv.I2);
  const double l = stretch;
  switch (deformation) {
    case Deformation::Uniaxial: return 2.0 * (l - 1.0 / (l * l)) * (d.d1 + d.d2 / l);
    case Deformation::Equibiaxial: return 2.0 * (l - std::pow(l, -5.0)) * (d.d1 + l * l * d.d2);
    case Deformation::PureShear: return 2.0 * (l - std::pow(l, -3.0)) * (d.d1 + d.d2);
  }
  throw std::logic_error("nominal_stress: unknown deformation");
}

double sphere_pressure(const Material& material, double rest_radius_mm, double rest_thickness_mm, double stretch) {
  return 2.0 * rest_thickness_mm / rest_radius_mm * nominal_stress(material, Deformation::Equibiaxial, stretch) /
         (stretch * stretch);
}

}  // namespace balloon
