#pragma once
/// Incompressible rubber laws as strain-energy densities Psi(I1, I2) (MPa), and the SPEC syntax
/// (`hart-smith:G=0.1,k1=3e-4,k2=1.0`) that names a law and its constants at the user-facing edge.
#include <array>
#include <string>
#include <vector>

#include "result.hpp"

namespace balloon {

enum class MaterialModel { NeoHookean, MooneyRivlin, HartSmith };

/// A rubber law and its constants. Moduli in MPa; k1 and k2 dimensionless.
///  - NeoHookean:   Psi = mu/2 (I1 - 3)                        params = {mu}
///  - MooneyRivlin: Psi = C1 (I1 - 3) + C2 (I2 - 3)            params = {C1, C2}
///  - HartSmith:    dPsi/dI1 = G exp(k1 (I1-3)^2),
///                  dPsi/dI2 = G k2 / I2          (paper eq. 16) params = {G, k1, k2}
///    Our k2 is the paper's, as written in eq. 16. Part of the literature writes dPsi/dI2 = 3 G k2 / I2;
///    its k2 is three times smaller than ours for the same rubber.
struct Material {
  MaterialModel model = MaterialModel::NeoHookean;
  std::array<double, 3> params{0.0, 0.0, 0.0};
  std::string name;  ///< preset or library name, empty for inline specs

  /// Small-strain shear modulus (MPa): mu, 2(C1+C2), 2G(1+k2/3).
  double shear_modulus() const;
};

/// Psi and its first and second derivatives with respect to the invariants I1, I2 (MPa).
struct InvariantDerivatives {
  double psi = 0, d1 = 0, d2 = 0, d11 = 0, d12 = 0, d22 = 0;
};

/// Evaluates the law at (I1, I2). For incompressible membranes I1 >= 3 and I2 >= 3.
InvariantDerivatives strain_energy(const Material& material, double I1, double I2);

/// Model name as in the SPEC syntax: "neo-hookean", "mooney-rivlin", "hart-smith".
std::string model_name(MaterialModel model);
/// Parameter names for the model, in params order, as in the SPEC syntax.
std::vector<std::string> parameter_names(MaterialModel model);
/// Parses a model name; fails with a message listing the known models.
Result<MaterialModel> parse_model_name(const std::string& name);

/// The leading modulus (mu, C1, G) a material may have (MPa): 1 Pa to 100 GPa (C2: 0 to 100 GPa).
constexpr double MIN_MODULUS_MPA = 1e-6;
constexpr double MAX_MODULUS_MPA = 1e5;
/// Hart-Smith's stiffening k1 (dimensionless) may be 0 to this.
constexpr double MAX_HART_SMITH_K1 = 100.0;

/// Parses `model:name=value,...` (every parameter required, moduli within the bounds above, k1 >= 0, k2 >= 0),
/// or a preset name (`silicone`, `latex`).
Result<Material> parse_material_spec(const std::string& spec);
/// Checks that the constants are finite and physical; returns an empty string when they are.
std::string material_problem(const Material& material);
/// The SPEC string for a material, e.g. "hart-smith:G=0.1,k1=0.0003,k2=1".
std::string material_spec(const Material& material);

/// Built-in presets. Values and sources are in README.md.
Result<Material> preset_material(const std::string& name);
std::vector<std::string> preset_names();

}  // namespace balloon
