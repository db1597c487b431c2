#include "material/fitting.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "material/homogeneous_tests.hpp"

namespace balloon {
namespace {

Material hart_smith(double G, double k1, double k2) {
  Material m;
  m.model = MaterialModel::HartSmith;
  m.params = {G, k1, k2};
  return m;
}

std::string read_data(const std::string& name) {
  std::ifstream in(std::string(BALLOON_TEST_DATA_DIR) + "/materials/" + name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

MeasurementSet load(const std::string& name, TestKind kind) {
  auto set = parse_measurements(read_data(name), kind, name);
  if (!set.ok()) throw std::runtime_error(name + ": " + set.error());
  return *set;
}

/// Stress table sampled from `material` at `count` stretches in [lo, hi], with multiplicative Gaussian
/// noise of relative size `noise`.
MeasurementSet synthetic_table(const Material& material, TestKind kind, Deformation deformation, double lo, double hi,
                               int count, double noise, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  MeasurementSet set;
  set.kind = kind;
  set.label = "synthetic " + test_kind_name(kind);
  for (int i = 0; i < count; ++i) {
    const double l = lo + (hi - lo) * i / (count - 1);
    set.x.push_back(l);
    set.y.push_back(nominal_stress(material, deformation, l) * (1.0 + noise * normal(rng)));
  }
  return set;
}

MeasurementSet synthetic_bulge(const Material& material, int count, double noise, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  MeasurementSet set;
  set.kind = TestKind::Bulge;
  set.label = "synthetic bulge";
  set.disc_radius_mm = 30.0;  // the paper's rig: 6 cm opening
  set.thickness_mm = 0.5;
  for (int i = 0; i < count; ++i) set.x.push_back(1.05 + 1.35 * i / (count - 1));
  set.y = spherical_cap_bulge_pressures(material, set);
  for (auto& p : set.y) p *= 1.0 + noise * normal(rng);
  return set;
}

std::string regimes_text(const Regimes& r) {
  return std::string(r.inflection ? "I" : "-") + (r.stiffening ? "S" : "-");
}

std::string fit_row(const std::string& data, const FitResult& fit) {
  std::ostringstream out;
  const auto names = parameter_names(fit.material.model);
  std::ostringstream params;
  params << std::setprecision(4);
  for (size_t j = 0; j < names.size(); ++j) {
    params << (j ? " " : "") << names[j] << "=" << fit.material.params[j];
    if (j < fit.std_errors.size()) params << "(+-" << std::setprecision(2) << fit.std_errors[j] << std::setprecision(4) << ")";
  }
  out << std::left << std::setw(26) << data << std::setw(14) << model_name(fit.material.model) << std::setw(64) << params.str()
      << std::right << std::setprecision(3) << std::setw(10) << fit.rms_residual << std::setw(10) << fit.max_residual
      << std::setw(9) << fit.rms_relative_residual << std::setw(9) << fit.max_relative_residual << std::setw(5) << fit.points
      << "   data " << (fit.data_inflection ? "I" : "-") << (fit.data_stiffening ? "S" : "-") << " model "
      << (fit.model_inflection ? "I" : "-") << (fit.model_stiffening ? "S" : "-") << (fit.converged ? "" : "  NOT CONVERGED");
  return out.str();
}

std::string table_header() {
  std::ostringstream out;
  out << std::left << std::setw(26) << "data" << std::setw(14) << "model" << std::setw(64) << "params (MPa; k1,k2 none) (+-std err)"
      << std::right << std::setw(10) << "rms MPa" << std::setw(10) << "max MPa" << std::setw(9) << "rms rel" << std::setw(9)
      << "max rel" << std::setw(5) << "n" << "   regimes (I inflection, S stiffening)";
  return out.str();
}

const MaterialModel ALL_MODELS[] = {MaterialModel::NeoHookean, MaterialModel::MooneyRivlin, MaterialModel::HartSmith};

TEST(Fitting, DetectRegimesOnKnownCurves) {
  std::vector<double> x, line, cubic, concave;
  for (int i = 0; i <= 100; ++i) {
    const double t = i / 100.0;
    x.push_back(t);
    line.push_back(2 * t);
    cubic.push_back(t - 1.5 * t * t + 1.0 * t * t * t);  // slope 1 - 3t + 3t^2: min at t = 0.5, then rises
    concave.push_back(std::sqrt(t + 0.01));
  }
  EXPECT_FALSE(detect_regimes(x, line).inflection);
  EXPECT_FALSE(detect_regimes(x, line).stiffening);
  EXPECT_TRUE(detect_regimes(x, cubic).inflection);
  EXPECT_TRUE(detect_regimes(x, cubic).stiffening);
  EXPECT_FALSE(detect_regimes(x, concave).inflection);
  EXPECT_FALSE(detect_regimes(x, concave).stiffening);
}

TEST(Fitting, SyntheticHartSmithRoundTripWithOnePercentNoise) {
  const auto truth = hart_smith(0.15, 2e-3, 0.8);
  std::mt19937 rng(20240611);
  const std::vector<MeasurementSet> sets = {
      synthetic_table(truth, TestKind::Uniaxial, Deformation::Uniaxial, 1.05, 5.0, 20, 0.01, rng),
      synthetic_table(truth, TestKind::Equibiaxial, Deformation::Equibiaxial, 1.05, 5.0, 20, 0.01, rng)};
  const auto fit = fit_material(MaterialModel::HartSmith, sets);
  ASSERT_TRUE(fit.ok()) << fit.error();
  std::cout << table_header() << "\n" << fit_row("synthetic UT+ET", *fit) << "\n";
  EXPECT_TRUE(fit->converged) << fit->message;
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(fit->material.params[j] / truth.params[j], 1.0, 0.05) << parameter_names(MaterialModel::HartSmith)[j];
    ASSERT_EQ(fit->std_errors.size(), 3u);
    EXPECT_GT(fit->std_errors[j], 0.0);
    // The truth lies within 4 standard errors: the uncertainty estimate is of the right size.
    EXPECT_LT(std::abs(fit->material.params[j] - truth.params[j]), 4.0 * fit->std_errors[j]) << j;
  }
  EXPECT_NEAR(fit->rms_relative_residual, 0.01, 0.004);  // the fit explains all but the noise
  EXPECT_EQ(fit->points, 40);
  EXPECT_EQ(fit->residual_unit, "MPa");
}

TEST(Fitting, ExactDataOfEachModelIsRecoveredWithoutNoise) {
  Material nh, mr;
  nh.model = MaterialModel::NeoHookean;
  nh.params = {0.4, 0, 0};
  mr.model = MaterialModel::MooneyRivlin;
  mr.params = {0.2, 0.03, 0};
  std::mt19937 rng(1);
  for (const auto& truth : {nh, mr, hart_smith(0.2, 5e-4, 1.5)}) {
    const std::vector<MeasurementSet> sets = {
        synthetic_table(truth, TestKind::Uniaxial, Deformation::Uniaxial, 1.0, 4.0, 15, 0.0, rng),
        synthetic_table(truth, TestKind::PureShear, Deformation::PureShear, 1.0, 3.0, 15, 0.0, rng)};
    const auto fit = fit_material(truth.model, sets);
    ASSERT_TRUE(fit.ok()) << fit.error();
    for (size_t j = 0; j < parameter_names(truth.model).size(); ++j)
      EXPECT_NEAR(fit->material.params[j] / truth.params[j], 1.0, 1e-4) << model_name(truth.model) << " param " << j;
    EXPECT_LT(fit->rms_relative_residual, 1e-6);
  }
}

TEST(Fitting, BulgeRoundTripWithSphericalCapModelAndTenPointsIsFast) {
  const auto truth = hart_smith(0.1, 3e-3, 1.0);
  std::mt19937 rng(7);
  const auto set = synthetic_bulge(truth, 10, 0.0, rng);
  const auto start = std::chrono::steady_clock::now();
  const auto fit = fit_material(MaterialModel::HartSmith, {set});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(fit.ok()) << fit.error();
  std::cout << "10-point Hart-Smith bulge fit: " << seconds << " s, " << fit->evaluations << " residual evaluations\n";
  EXPECT_EQ(fit->residual_unit, "kPa");
  EXPECT_EQ(fit->points, 10);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(fit->material.params[j] / truth.params[j], 1.0, 1e-3) << j;
  EXPECT_GT(set.y.back(), 1.0);  // kPa scale, not MPa
}

TEST(Fitting, BulgeModelCallbackReplacesTheSphericalCap) {
  const auto truth = hart_smith(0.1, 3e-3, 1.0);
  std::mt19937 rng(8);
  const auto set = synthetic_bulge(truth, 12, 0.01, rng);
  int calls = 0;
  FitOptions options;
  options.bulge_model = [&calls](const Material& m, const MeasurementSet& query) {
    ++calls;
    EXPECT_EQ(query.disc_radius_mm, 30.0);
    auto p = spherical_cap_bulge_pressures(m, query);
    for (auto& v : p) v *= 2.0;  // a model twice as stiff must give half the modulus
    return p;
  };
  const auto plain = fit_material(MaterialModel::HartSmith, {set});
  const auto doubled = fit_material(MaterialModel::HartSmith, {set}, options);
  ASSERT_TRUE(plain.ok() && doubled.ok());
  EXPECT_GT(calls, 10);
  EXPECT_NEAR(doubled->material.params[0] / plain->material.params[0], 0.5, 1e-3);
  EXPECT_NEAR(doubled->material.params[1] / plain->material.params[1], 1.0, 1e-3);
}

TEST(Fitting, BadInputGivesClearErrors) {
  const auto expect_error = [](const Result<FitResult>& r, const std::string& expected) {
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find(expected), std::string::npos) << r.error();
  };
  expect_error(fit_material(MaterialModel::HartSmith, {}), "no measurements to fit");
  MeasurementSet two;
  two.kind = TestKind::Uniaxial;
  two.label = "two.csv";
  two.x = {1.1, 1.5};
  two.y = {0.1, 0.3};
  expect_error(fit_material(MaterialModel::HartSmith, {two}), "only 2 data points for the 3 parameters of hart-smith");
  EXPECT_TRUE(fit_material(MaterialModel::MooneyRivlin, {two}).ok());
  MeasurementSet zero = two;
  zero.x = {1.0, 1.0 + 1e-9};
  zero.y = {0.0, 0.0};
  expect_error(fit_material(MaterialModel::NeoHookean, {zero}), "two.csv: all values are zero");
  MeasurementSet bulge;
  bulge.kind = TestKind::Bulge;
  bulge.label = "rig.csv";
  bulge.x = {1.1, 1.2, 1.4};
  bulge.y = {1, 2, 3};
  expect_error(fit_material(MaterialModel::NeoHookean, {bulge}), "rig.csv: bulge data needs a disc radius > 0 mm");
  MeasurementSet backwards = two;
  backwards.x = {1.5, 1.1};
  expect_error(fit_material(MaterialModel::NeoHookean, {backwards}), "two.csv: point 2: stretch 1.1 is not larger");
}

/// Fits every model to every real table alone and jointly per material; prints the table (and writes it
/// to $BALLOON_FIT_REPORT when set) and checks the paper's finding on Treloar's equibiaxial data.
TEST(Fitting, RealMeasurementsAloneAndJointly) {
  const auto treloar_ut = load("treloar1944_ut.csv", TestKind::Uniaxial);
  const auto treloar_et = load("treloar1944_et.csv", TestKind::Equibiaxial);
  const auto treloar_ps = load("treloar1944_ps.csv", TestKind::PureShear);
  const auto meunier_ut = load("meunier2008_silicone_ut.csv", TestKind::Uniaxial);
  const auto meunier_et = load("meunier2008_silicone_et.csv", TestKind::Equibiaxial);
  const auto meunier_ps = load("meunier2008_silicone_ps.csv", TestKind::PureShear);
  const std::vector<std::pair<std::string, std::vector<MeasurementSet>>> cases = {
      {"treloar1944 UT", {treloar_ut}},
      {"treloar1944 ET", {treloar_et}},
      {"treloar1944 PS", {treloar_ps}},
      {"treloar1944 UT+ET+PS", {treloar_ut, treloar_et, treloar_ps}},
      {"meunier2008 UT", {meunier_ut}},
      {"meunier2008 ET", {meunier_et}},
      {"meunier2008 PS", {meunier_ps}},
      {"meunier2008 UT+ET+PS", {meunier_ut, meunier_et, meunier_ps}},
  };
  std::ostringstream report;
  report << "Fits of the real measurements (tests/data/materials, see PROVENANCE.md), written by\n"
         << "balloon_core_tests --gtest_filter=Fitting.RealMeasurementsAloneAndJointly\n"
         << "Residuals: rms/max of |P_model - P_data| in MPa of nominal stress over all points; rel = relative\n"
         << "residuals (P_model - P_data) / max(|P_data|, 1% of the set's max), the fitted quantity.\n"
         << "Regimes of the headline set (ET if present, as balloon curve P_ET/l^2; else P(l)).\n"
         << "Meunier UT: the 16 compression rows (stretch < 1) are dropped.\n\n"
         << table_header() << "\n";
  std::map<std::string, double> relative_rms;
  std::map<std::string, FitResult> fits;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& [name, sets] : cases) {
    for (auto model : ALL_MODELS) {
      const auto fit = fit_material(model, sets);
      ASSERT_TRUE(fit.ok()) << name << ": " << fit.error();
      EXPECT_TRUE(fit->converged) << name << " " << model_name(model) << ": " << fit->message;
      report << fit_row(name, *fit) << "\n";
      if (sets.size() > 1)
        for (const auto& s : fit->sets)
          report << "    " << std::left << std::setw(32) << s.label << std::right << std::setprecision(3) << " rms " << s.rms_residual
                 << " MPa, max " << s.max_residual << " MPa, rms rel " << s.rms_relative_residual << ", regimes data "
                 << regimes_text(s.data_regimes) << " model " << regimes_text(s.model_regimes) << "\n";
      relative_rms[name + "/" + model_name(model)] = fit->rms_relative_residual;
      fits.emplace(name + "/" + model_name(model), *fit);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report << "\n" << cases.size() * 3 << " fits in " << std::setprecision(3) << seconds << " s\n";

  // Treloar ET fitted by absolute least squares (relative_floor = 1: every point weighted 1 / max stress),
  // to show the ranking does not depend on the residual weighting.
  FitOptions absolute;
  absolute.relative_floor = 1.0;
  std::map<std::string, double> absolute_rms;
  report << "\nTreloar ET fitted by absolute least squares (relative_floor = 1):\n";
  for (auto model : ALL_MODELS) {
    const auto fit = fit_material(model, {treloar_et}, absolute);
    ASSERT_TRUE(fit.ok());
    report << fit_row("treloar1944 ET (absolute)", *fit) << "\n";
    absolute_rms[model_name(model)] = fit->rms_residual;
  }

  // Presets: our own Hart-Smith fits to the equibiaxial tables, the test closest to a balloon wall (and to
  // the paper's membrane inflation). Silicone: Meunier's ET alone; it predicts his UT and PS tables about
  // as well as the joint UT+ET+PS fit does (cross-check below) and ET twice as closely. Latex: Treloar's
  // ET alone (his UT runs to stretch 7.6, into strain crystallisation).
  const auto& silicone = fits.at("meunier2008 ET/hart-smith");
  const auto& latex = fits.at("treloar1944 ET/hart-smith");
  const auto& silicone_joint = fits.at("meunier2008 UT+ET+PS/hart-smith");
  const auto relative_rms_on = [](const Material& m, const MeasurementSet& set) {
    double largest = 0.0, sum = 0.0;
    for (double v : set.y) largest = std::max(largest, std::abs(v));
    const auto y = model_values(m, set, set.x);
    for (size_t i = 0; i < y.size(); ++i) {
      const double r = (y[i] - set.y[i]) / std::max(std::abs(set.y[i]), 0.01 * largest);
      sum += r * r;
    }
    return std::sqrt(sum / y.size());
  };
  report << "\nCross-check, rms relative residual of each silicone candidate on each Meunier test:\n";
  for (const auto* candidate : {&silicone, &silicone_joint})
    report << "  " << material_spec(candidate->material) << ": UT " << relative_rms_on(candidate->material, meunier_ut) << ", ET "
           << relative_rms_on(candidate->material, meunier_et) << ", PS " << relative_rms_on(candidate->material, meunier_ps) << "\n";
  report << "\nPRESET silicone: " << material_spec(silicone.material) << "   (Hart-Smith fit to Meunier 2008 ET, "
         << silicone.points << " points; std errors G " << silicone.std_errors[0] << ", k1 " << silicone.std_errors[1] << ", k2 "
         << silicone.std_errors[2] << "; rms " << silicone.rms_residual << " MPa, rms rel " << silicone.rms_relative_residual
         << "; small-strain shear modulus " << silicone.material.shear_modulus() << " MPa)\n";
  report << "PRESET latex: " << material_spec(latex.material) << "   (Hart-Smith fit to Treloar 1944 ET, " << latex.points
         << " points; std errors G " << latex.std_errors[0] << ", k1 " << latex.std_errors[1] << ", k2 " << latex.std_errors[2]
         << "; rms " << latex.rms_residual << " MPa, rms rel " << latex.rms_relative_residual << "; small-strain shear modulus "
         << latex.material.shear_modulus() << " MPa)\n";
  report << "(k2 as in paper eq. 16: dPsi/dI2 = G k2 / I2.) Reproduce with: balloon fit-material\n"
         << "  tests/data/materials/meunier2008_silicone_et.csv --test equibiaxial --model hart-smith  (silicone)\n"
         << "  tests/data/materials/treloar1944_et.csv --test equibiaxial --model hart-smith          (latex)\n";
  std::cout << report.str();
  if (const char* path = std::getenv("BALLOON_FIT_REPORT")) std::ofstream(path) << report.str();

  // The paper's finding (sec. 4.2) on Treloar's membrane-inflation data: Hart-Smith fits far better. In
  // MPa of nominal stress it is 5-9 times closer than Neo-Hookean and Mooney-Rivlin, whether the fit
  // minimizes relative or absolute residuals.
  const auto& hs = fits.at("treloar1944 ET/hart-smith");
  EXPECT_LT(hs.rms_residual, 0.5 * fits.at("treloar1944 ET/neo-hookean").rms_residual);
  EXPECT_LT(hs.rms_residual, 0.5 * fits.at("treloar1944 ET/mooney-rivlin").rms_residual);
  EXPECT_LT(hs.rms_residual, 0.025);  // MPa, on stresses up to 2.4 MPa
  EXPECT_LT(absolute_rms["hart-smith"], 0.5 * absolute_rms["neo-hookean"]);
  EXPECT_LT(absolute_rms["hart-smith"], 0.5 * absolute_rms["mooney-rivlin"]);
  // In relative residuals the margin is smaller: Treloar's first point (stretch 1.027) sits 30% above
  // every model's curve (a digitising error at small strain) and dominates all three relative rms values.
  EXPECT_LT(relative_rms["treloar1944 ET/hart-smith"], relative_rms["treloar1944 ET/mooney-rivlin"]);
  EXPECT_LT(relative_rms["treloar1944 ET/hart-smith"], relative_rms["treloar1944 ET/neo-hookean"]);
  // ...and only Hart-Smith stiffens again at the end of the balloon curve, as the data do.
  const auto& hs_fit = fits.at("treloar1944 ET/hart-smith");
  EXPECT_TRUE(hs_fit.data_stiffening);
  EXPECT_TRUE(hs_fit.model_stiffening);
  EXPECT_FALSE(fits.at("treloar1944 ET/neo-hookean").model_stiffening);
  EXPECT_FALSE(fits.at("treloar1944 ET/mooney-rivlin").model_stiffening);
}

}  // namespace
}  // namespace balloon
