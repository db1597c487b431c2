#include "material/material.hpp"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>

namespace balloon {
namespace {

/// F(t) = integral_0^t exp(k s^2) ds, the Hart-Smith I1 energy term (paper eq. 16 integrated).
/// The power series t * sum (k t^2)^n / (n! (2n+1)) has only positive terms, so it is accurate for every
/// argument; past exp overflow the energy is infinite anyway.
double integral_of_exp_square(double k, double t) {
  const double a = k * t * t;
  if (a > 700.0) return std::numeric_limits<double>::infinity();
  double term = 1.0;  // a^n / n!
  double sum = 1.0;
  for (int n = 1; n < 5000; ++n) {
    term *= a / n;
    const double contribution = term / (2.0 * n + 1.0);
    sum += contribution;
    if (contribution < 1e-17 * sum) break;
  }
  return t * sum;
}

struct ModelInfo {
  MaterialModel model;
  const char* name;
  std::vector<std::string> params;
};

const std::vector<ModelInfo>& model_table() {
  static const std::vector<ModelInfo> table = {
      {MaterialModel::NeoHookean, "neo-hookean", {"mu"}},
      {MaterialModel::MooneyRivlin, "mooney-rivlin", {"C1", "C2"}},
      {MaterialModel::HartSmith, "hart-smith", {"G", "k1", "k2"}},
  };
  return table;
}

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

}  // namespace

double Material::shear_modulus() const {
  switch (model) {
    case MaterialModel::NeoHookean: return params[0];
    case MaterialModel::MooneyRivlin: return 2.0 * (params[0] + params[1]);
    case MaterialModel::HartSmith: return 2.0 * params[0] * (1.0 + params[2] / 3.0);
  }
  return 0.0;
}

InvariantDerivatives strain_energy(const Material& material, double I1, double I2) {
  InvariantDerivatives d;
  const auto& p = material.params;
  switch (material.model) {
    case MaterialModel::NeoHookean:
      d.psi = 0.5 * p[0] * (I1 - 3.0);
      d.d1 = 0.5 * p[0];
      break;
    case MaterialModel::MooneyRivlin:
      d.psi = p[0] * (I1 - 3.0) + p[1] * (I2 - 3.0);
      d.d1 = p[0];
      d.d2 = p[1];
      break;
    case MaterialModel::HartSmith: {
      const double G = p[0], k1 = p[1], k2 = p[2];
      const double t = I1 - 3.0;
      const double e = std::exp(k1 * t * t);
      d.psi = G * integral_of_exp_square(k1, t) + G * k2 * std::log(I2 / 3.0);
      d.d1 = G * e;
      d.d11 = G * e * 2.0 * k1 * t;
      d.d2 = G * k2 / I2;
      d.d22 = -G * k2 / (I2 * I2);
      break;
    }
  }
  return d;
}

std::string model_name(MaterialModel model) {
  for (const auto& info : model_table())
    if (info.model == model) return info.name;
  return "unknown";
}

std::vector<std::string> parameter_names(MaterialModel model) {
  for (const auto& info : model_table())
    if (info.model == model) return info.params;
  return {};
}

Result<MaterialModel> parse_model_name(const std::string& name) {
  for (const auto& info : model_table())
    if (name == info.name) return info.model;
  return fail("unknown material model '" + name + "' (known: neo-hookean, mooney-rivlin, hart-smith)");
}

std::string material_problem(const Material& material) {
  const auto names = parameter_names(material.model);
  for (size_t i = 0; i < names.size(); ++i) {
    if (!std::isfinite(material.params[i])) return "material parameter " + names[i] + " is not a finite number";
  }
  const auto& p = material.params;
  // A leading modulus outside 1 Pa .. 100 GPa is no rubber's, and far outside it the forces round to 0 or
  // overflow (mu = 1e-300 MPa: every shape "balanced" at once, converged after 0 Newton steps). A second
  // modulus (C2) has no lower bound but 0: a fit drives an unneeded one towards 0, not to it.
  const auto modulus_problem = [](const std::string& name, double value, bool leading) -> std::string {
    if ((leading ? value >= MIN_MODULUS_MPA : value >= 0.0) && value <= MAX_MODULUS_MPA) return "";
    std::ostringstream out;
    out << "material parameter " << name << " must be a modulus from " << (leading ? MIN_MODULUS_MPA : 0.0) << " to "
        << MAX_MODULUS_MPA << " MPa (" << (leading ? "1 Pa" : "0") << " to 100 GPa), got " << value;
    return out.str();
  };
  switch (material.model) {
    case MaterialModel::NeoHookean:
      return modulus_problem("mu", p[0], true);
    case MaterialModel::MooneyRivlin:
      if (auto problem = modulus_problem("C1", p[0], true); !problem.empty()) return problem;
      return modulus_problem("C2", p[1], false);
    case MaterialModel::HartSmith:
      if (auto problem = modulus_problem("G", p[0], true); !problem.empty()) return problem;
      // exp(k1 (I1 - 3)^2): far above the fits (3e-4 to 0.03) it overflows at once (k1 = 1e300: a non-finite
      // residual at the rest shape itself); up to MAX_HART_SMITH_K1 it overflows only at a stretch the
      // inflation then names (`Inflation.ARubberThatStiffensBeyondDoublePrecisionSaysSoInPhysicalTerms`).
      if (!(p[1] >= 0 && p[1] <= MAX_HART_SMITH_K1)) {
        std::ostringstream out;
        out << "material parameter k1 must be from 0 to " << MAX_HART_SMITH_K1
            << " (fitted rubbers: 3e-4 to 0.03), got " << p[1];
        return out.str();
      }
      if (p[2] < 0) return "material parameter k2 must be non-negative";
      break;
  }
  return "";
}

Result<Material> parse_material_spec(const std::string& raw_spec) {
  const std::string spec = trim(raw_spec);
  if (spec.empty()) return fail("empty material spec (expected e.g. 'hart-smith:G=0.1,k1=3e-4,k2=1.0' or 'silicone')");
  const auto colon = spec.find(':');
  if (colon == std::string::npos) {
    auto preset = preset_material(spec);
    if (preset) return preset;
    return fail("unknown material '" + spec + "': not a preset (silicone, latex) and not of the form model:name=value,...");
  }
  auto model = parse_model_name(trim(spec.substr(0, colon)));
  if (!model) return fail(model.error());
  Material material;
  material.model = *model;
  const auto names = parameter_names(material.model);
  std::map<std::string, double> values;
  std::stringstream list(spec.substr(colon + 1));
  std::string item;
  while (std::getline(list, item, ',')) {
    item = trim(item);
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos) return fail("material parameter '" + item + "' has no value (expected name=value)");
    const std::string key = trim(item.substr(0, eq));
    const std::string text = trim(item.substr(eq + 1));
    bool known = false;
    for (const auto& n : names) known = known || n == key;
    if (!known) {
      std::string all;
      for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
      return fail("unknown parameter '" + key + "' for " + model_name(material.model) + " (expected " + all + ")");
    }
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (text.empty() || end == nullptr || *end != '\0') return fail("material parameter " + key + "='" + text + "' is not a number");
    if (values.count(key)) return fail("material parameter " + key + " given twice");
    values[key] = value;
  }
  for (size_t i = 0; i < names.size(); ++i) {
    auto it = values.find(names[i]);
    if (it == values.end()) return fail("material parameter " + names[i] + " missing for " + model_name(material.model));
    material.params[i] = it->second;
  }
  if (auto problem = material_problem(material); !problem.empty()) return fail(problem);
  return material;
}

std::string material_spec(const Material& material) {
  std::ostringstream out;
  out.precision(6);
  out << model_name(material.model) << ':';
  const auto names = parameter_names(material.model);
  for (size_t i = 0; i < names.size(); ++i) out << (i ? "," : "") << names[i] << '=' << material.params[i];
  return out.str();
}

Result<Material> preset_material(const std::string& name) {
  // Hart-Smith fits of our own to equibiaxial tension data (the test closest to a balloon wall);
  // data, command and residuals in README.md ("Materials").
  //  silicone: Meunier et al. 2008, unfilled silicone rubber, ET, 14 points, rms 0.0058 MPa.
  //  latex:    Treloar 1944, vulcanised natural rubber (the usual stand-in for latex), ET, 16 points, rms 0.019 MPa.
  Material m;
  m.model = MaterialModel::HartSmith;
  m.name = name;
  if (name == "silicone") {
    m.params = {0.131735, 0.0260802, 0.971018};
  } else if (name == "latex") {
    m.params = {0.181396, 0.00029924, 0.490755};
  } else {
    return fail("unknown material preset '" + name + "' (known: silicone, latex)");
  }
  return m;
}

std::vector<std::string> preset_names() { return {"silicone", "latex"}; }

}  // namespace balloon
