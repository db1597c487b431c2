// The forward simulator against exact solutions: a thin sphere follows p = h Psi'(l) / (R l^2) for every
// material, on both sides of a pressure maximum, and stiff or extreme cases end without NaN.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/mesh/mesh_test_helpers.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/mesh_geometry.hpp"
#include "mesh/mesh_io.hpp"
#include "solve/inflation.hpp"
#include "solve/quantity_text.hpp"

namespace balloon {
namespace {

Material make(MaterialModel model, double a, double b = 0, double c = 0) {
  Material m;
  m.model = model;
  m.params = {a, b, c};
  return m;
}

/// Closed-form pressure (kPa) of a thin incompressible sphere of rest radius R and thickness h at
/// equibiaxial stretch l: energy 4 pi R^2 h Psi(l) against p * 4/3 pi R^3 l^3.
double sphere_pressure_kpa(const Material& material, double h, double R, double l) {
  const double I1 = 2 * l * l + std::pow(l, -4), I2 = std::pow(l, 4) + 2 * std::pow(l, -2);
  const double dI1 = 4 * l - 4 * std::pow(l, -5), dI2 = 4 * std::pow(l, 3) - 4 * std::pow(l, -3);
  const InvariantDerivatives d = strain_energy(material, I1, I2);
  return 1e3 * h * (d.d1 * dI1 + d.d2 * dI2) / (R * l * l);
}

double mesh_volume(const TriMesh& m) { return enclosed_volume(m.vertices, m.faces); }
double mesh_area(const TriMesh& m) { return surface_area(m.vertices, m.faces); }

/// `file` of tests/data/meshes, scaled to a `diagonal_mm` bounding-box diagonal.
TriMesh corpus_mesh(const std::string& file, double diagonal_mm) {
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/" + file);
  if (!mesh.ok()) throw std::runtime_error(mesh.error());
  mesh->vertices *= diagonal_mm / bounding_box_diagonal(mesh->vertices);
  return *mesh;
}

/// Inflates `file` of tests/data/meshes, scaled to a `diagonal_mm` bounding-box diagonal, 0.5 mm thick,
/// with the material `spec`, to `volume_ratio`.
InflationResult inflate_corpus_mesh(const std::string& file, double diagonal_mm, const std::string& spec,
                                    double volume_ratio) {
  InflationOptions options;
  options.material = *parse_material_spec(spec);
  options.thickness_mm = 0.5;
  options.volume_ratio = volume_ratio;
  return inflate(corpus_mesh(file, diagonal_mm), options);
}

/// A step-count regression check: `result` converged to `volume_ratio` in fewer than `max_newton_steps`.
void expect_converges_within(const InflationResult& result, double volume_ratio, int max_newton_steps) {
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.volume_ratio, volume_ratio, volume_ratio * 1e-6);
  EXPECT_LT(result.newton_iterations, max_newton_steps);
}

struct SphereCase {
  const char* label;
  Material material;
  std::vector<double> stretches;
};

class SphereLawTest : public ::testing::TestWithParam<SphereCase> {};

TEST_P(SphereLawTest, PressureMatchesClosedFormWithinHalfPercent) {
  const SphereCase c = GetParam();
  const TriMesh sphere = make_icosphere(10.0, 4);  // 2562 vertices
  ASSERT_GE(sphere.vertex_count(), 2500);
  // The polyhedron's own radius: the sphere with its volume-to-area ratio.
  const double radius = 3.0 * mesh_volume(sphere) / mesh_area(sphere);
  const double h = 0.5;
  Positions previous = sphere.vertices;
  for (double l : c.stretches) {
    InflationOptions options;
    options.material = c.material;
    options.thickness_mm = h;
    options.control = InflationControl::VolumeRatio;
    options.volume_ratio = l * l * l;
    const InflationResult result = inflate(sphere, options, &previous);
    ASSERT_TRUE(result.converged) << c.label << " l=" << l << ": " << result.message;
    previous = result.deformed;
    const double stretch = std::cbrt(result.volume_ratio);
    EXPECT_NEAR(stretch, l, 1e-6 * l);
    const double expected = sphere_pressure_kpa(c.material, h, radius, stretch);
    EXPECT_NEAR(result.pressure_kpa, expected, 5e-3 * std::abs(expected)) << c.label << " at stretch " << l;
    // The rigid support carries no load and the shape stays round.
    const Eigen::RowVector3d center = result.deformed.colwise().mean();
    const Eigen::VectorXd centered = (result.deformed.rowwise() - center).rowwise().norm();
    EXPECT_LT((centered.array() - centered.mean()).abs().maxCoeff(), 1e-2 * centered.mean()) << c.label;
    EXPECT_LT(result.residual_norm, 1e-6 * result.pressure_kpa * 1e-3 * 4 * M_PI * radius * radius);
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllMaterials, SphereLawTest,
    ::testing::Values(
        // Neo-Hookean peaks at l = 7^(1/6) = 1.383: stretches past it are reached by volume control only.
        SphereCase{"neo_hookean", make(MaterialModel::NeoHookean, 0.3), {1.1, 1.3, 1.5, 2.0, 2.5, 3.0}},
        SphereCase{"mooney_rivlin", make(MaterialModel::MooneyRivlin, 0.18, 0.02), {1.1, 1.3, 1.6, 2.0, 2.5, 3.0}},
        SphereCase{"hart_smith", make(MaterialModel::HartSmith, 0.1, 3e-4, 1.0), {1.1, 1.5, 2.0, 3.0, 4.0, 5.0}}),
    [](const auto& test_info) { return std::string(test_info.param.label); });

TEST(Inflation, PressureControlFindsTheAscendingBranch) {
  const TriMesh sphere = make_icosphere(10.0, 3);
  const Material nh = make(MaterialModel::NeoHookean, 0.3);
  const double radius = 3.0 * mesh_volume(sphere) / mesh_area(sphere);
  InflationOptions options;
  options.material = nh;
  options.control = InflationControl::Pressure;
  const double peak = sphere_pressure_kpa(nh, 0.5, radius, std::pow(7.0, 1.0 / 6.0));
  options.pressure_kpa = 0.8 * peak;
  const InflationResult result = inflate(sphere, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.pressure_kpa, 0.8 * peak, 1e-9 * peak);
  const double stretch = std::cbrt(result.volume_ratio);
  EXPECT_LT(stretch, std::pow(7.0, 1.0 / 6.0));
  EXPECT_NEAR(sphere_pressure_kpa(nh, 0.5, radius, stretch), 0.8 * peak, 5e-3 * peak);
}

TEST(Inflation, PressureAboveTheMaximumIsReportedNotCrashed) {
  const TriMesh sphere = make_icosphere(10.0, 2);
  InflationOptions options;
  options.material = make(MaterialModel::NeoHookean, 0.3);
  options.control = InflationControl::Pressure;
  options.pressure_kpa = 100.0;  // the peak is about 19 kPa
  const InflationResult result = inflate(sphere, options);
  EXPECT_FALSE(result.converged);
  EXPECT_NE(result.message.find("maximum pressure"), std::string::npos) << result.message;
  EXPECT_TRUE(result.deformed.allFinite());
}

TEST(Inflation, ARubberThatStiffensBeyondDoublePrecisionSaysSoInPhysicalTerms) {
  // Hart-Smith with k1 = 10 (fitted rubbers: 3e-4 to 0.03): exp(k1 (I1 - 3)^2) overflows on the way to x27.
  // The path ends at its last equilibrium, where the pressure is already beyond 1 GPa, and says why in
  // those terms rather than only "non-finite residual".
  const TriMesh sphere = make_icosphere(10.0, 2);
  InflationOptions options;
  options.material = make(MaterialModel::HartSmith, 0.1, 10.0, 1.0);
  options.volume_ratio = 27.0;
  const InflationResult result = inflate(sphere, options);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.stop, InflationStop::NoEquilibrium);
  EXPECT_NE(result.message.find("outgrows the numbers a computer holds"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("far beyond what any rubber bears"), std::string::npos) << result.message;
  EXPECT_GT(result.pressure_kpa, 1e6);
  EXPECT_LT(result.volume_ratio, 27.0);
  EXPECT_TRUE(result.deformed.allFinite());
  // A stiffening that stays in range is followed to the end, with no such words.
  options.material = make(MaterialModel::HartSmith, 0.1, 0.01, 1.0);
  const InflationResult tame = inflate(sphere, options);
  EXPECT_TRUE(tame.converged) << tame.message;
  EXPECT_EQ(tame.message.find("outgrows"), std::string::npos) << tame.message;
}

TEST(Inflation, PressureAboveAMaximumThatTheStiffeningRubberClimbsBackToSnapsToTheFarBranch) {
  // A Mooney-Rivlin sphere's pressure rises to a maximum, falls, and climbs again as the C2 term
  // stiffens it: above the maximum the balloon snaps to the far branch, where p matches the closed form.
  const TriMesh sphere = make_icosphere(10.0, 3);
  // C2 / C1 = 1/6: the maximum at a stretch of 1.58, the minimum at 2.37 (3% lower), 1.05 times the
  // maximum again at 3.64.
  const Material rubber = make(MaterialModel::MooneyRivlin, 0.18, 0.03);
  const double radius = 3.0 * mesh_volume(sphere) / mesh_area(sphere);
  double peak = 0.0, peak_stretch = 1.0;
  for (double l = 1.01; l < 2.0; l += 0.001) {
    if (sphere_pressure_kpa(rubber, 0.5, radius, l) > peak) {
      peak = sphere_pressure_kpa(rubber, 0.5, radius, l);
      peak_stretch = l;
    }
  }
  InflationOptions options;
  options.material = rubber;
  options.control = InflationControl::Pressure;
  options.pressure_kpa = 1.05 * peak;
  const InflationResult result = inflate(sphere, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.pressure_kpa, 1.05 * peak, 1e-9 * peak);
  EXPECT_NE(result.message.find("snaps"), std::string::npos) << result.message;
  // It names the maximum it passed, not the path's last step beyond the target.
  const size_t named = result.message.find("maximum of ");
  ASSERT_NE(named, std::string::npos) << result.message;
  EXPECT_NEAR(std::stod(result.message.substr(named + 11)), peak, 0.01 * peak) << result.message;
  const double stretch = std::cbrt(result.volume_ratio);
  EXPECT_GT(stretch, 2.0 * peak_stretch);  // past the maximum and the minimum after it
  EXPECT_NEAR(sphere_pressure_kpa(rubber, 0.5, radius, stretch), 1.05 * peak, 5e-3 * peak);
}

TEST(Inflation, PressureControlSettlesOnAShapeThatWrinklesBetweenTwoVolumeSteps) {
  // The knot's tube under a pressure its volume path reaches at x2: a Newton solve at that fixed pressure,
  // started between the two path points that bracket it, crept to its iteration limit (128 steps, "no
  // equilibrium found"); the bracket is now closed by volume-controlled solves.
  const InflationResult by_volume = inflate_corpus_mesh("knot.off", 200.0, "latex", 2.0);
  ASSERT_TRUE(by_volume.converged) << by_volume.message;
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/knot.off");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  mesh->vertices *= 200.0 / bounding_box_diagonal(mesh->vertices);
  InflationOptions options;
  options.material = *parse_material_spec("latex");
  options.control = InflationControl::Pressure;
  options.pressure_kpa = 0.9 * by_volume.pressure_kpa;
  const InflationResult result = inflate(*mesh, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.pressure_kpa, options.pressure_kpa, 1e-12 * options.pressure_kpa);
  EXPECT_GT(result.volume_ratio, 1.0);
  EXPECT_LT(result.volume_ratio, 2.0);
}

TEST(Inflation, BadOptionsAreReportedNotThrown) {
  const TriMesh sphere = make_icosphere(10.0, 1);
  InflationOptions options;
  options.material = make(MaterialModel::NeoHookean, 0.3);
  options.thickness_mm = -1;
  options.volume_ratio = 2;
  InflationResult result = inflate(sphere, options);
  EXPECT_FALSE(result.converged);
  EXPECT_NE(result.message.find("thickness"), std::string::npos);
  options.thickness_mm = 0.5;
  options.volume_ratio = std::nan("");
  result = inflate(sphere, options);
  EXPECT_FALSE(result.converged);
  EXPECT_NE(result.message.find("volume ratio"), std::string::npos);
}

struct ExtremeCase {
  const char* label;
  Material material;
  double thickness;
  double volume_ratio;
  int subdivisions;
};

class ExtremeInflationTest : public ::testing::TestWithParam<ExtremeCase> {};

TEST_P(ExtremeInflationTest, EndsWithoutNaNAndConvergesOrSaysWhy) {
  const ExtremeCase c = GetParam();
  const TriMesh sphere = make_icosphere(10.0, c.subdivisions);
  InflationOptions options;
  options.material = c.material;
  options.thickness_mm = c.thickness;
  options.volume_ratio = c.volume_ratio;
  const InflationResult result = inflate(sphere, options);
  EXPECT_TRUE(result.deformed.allFinite()) << c.label;
  EXPECT_TRUE(std::isfinite(result.pressure_kpa)) << c.label;
  if (!result.converged) {
    EXPECT_FALSE(result.message.empty()) << c.label;
  }
  // These cases are all solvable: a sphere has an equilibrium at every volume.
  EXPECT_TRUE(result.converged) << c.label << ": " << result.message;
  EXPECT_NEAR(result.volume_ratio, c.volume_ratio, 1e-6 * c.volume_ratio) << c.label;
}

INSTANTIATE_TEST_SUITE_P(
    Stiff, ExtremeInflationTest,
    ::testing::Values(ExtremeCase{"hart_smith_k1_1e_2", make(MaterialModel::HartSmith, 0.1, 1e-2, 1.0), 0.5, 64.0, 3},
                      ExtremeCase{"latex_volume_ratio_125", make(MaterialModel::HartSmith, 0.17, 3e-3, 0.5), 0.5, 125.0, 3},
                      ExtremeCase{"thin_0_05_mm", make(MaterialModel::NeoHookean, 0.3), 0.05, 8.0, 3},
                      ExtremeCase{"coarse_12_vertices", make(MaterialModel::MooneyRivlin, 0.18, 0.02), 0.5, 8.0, 0}),
    [](const auto& test_info) { return std::string(test_info.param.label); });

}  // namespace
}  // namespace balloon

namespace balloon {
namespace {

// Real meshes with slivers (hand, min angle 0.7 deg), flat faces and sharp edges (cube) and a bumpy
// surface: load, validate, and inflate to equilibrium at 100 mm size.
class SampleMeshInflationTest : public ::testing::TestWithParam<const char*> {};

TEST_P(SampleMeshInflationTest, InflatesToVolumeRatioEight) {
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/" + GetParam());
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  ASSERT_TRUE(validate_balloon_mesh(*mesh).ok());
  mesh->vertices *= 100.0 / bounding_box_diagonal(mesh->vertices);
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 8.0;
  const InflationResult result = inflate(*mesh, options);
  ASSERT_TRUE(result.converged) << GetParam() << ": " << result.message;
  EXPECT_NEAR(result.volume_ratio, 8.0, 1e-6);
  EXPECT_GT(result.pressure_kpa, 0.0);
  EXPECT_TRUE(result.deformed.allFinite());
  EXPECT_GT(result.max_stretch, result.mean_stretch);
}

INSTANTIATE_TEST_SUITE_P(Samples, SampleMeshInflationTest,
                         ::testing::Values("hand_fist.off", "cube_866.off", "stanford_bunny_1839.obj"),
                         [](const auto& test_info) {
                           std::string name = test_info.param;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

}  // namespace
}  // namespace balloon

namespace balloon {
namespace {

// CI's subset of bench_robustness (issue 10): corpus meshes at 200 mm as given, 0.5 mm thick, to the
// bench's largest ratio. Blob, cactus (flat), spool (coarse, flat ends) and fandisk (CAD edges) are quick;
// rotor with Neo-Hookean ended at "no equilibrium at volume ratio 1.03", and dino with latex and the knot
// at the time limit or at "no equilibrium at 1.55", before volume steps were resumed where they ended.
// The rotor's and the knot's equilibria pass through themselves (blades, strands): the answer is then that
// stop reason, with the equilibrium found. The dinosaur's membrane equilibrium did too (its limbs); with the
// sheet's bending (tried early on its creeping first volume step, or once more from the start when the
// membrane's equilibrium passes through itself) it reaches an equilibrium that does not.
struct CorpusCase {
  const char* label;
  const char* file;
  const char* material;
  double volume_ratio;
  InflationStop expected = InflationStop::Converged;
};

class CorpusInflationTest : public ::testing::TestWithParam<CorpusCase> {};

TEST_P(CorpusInflationTest, ConvergesToTheVolumeRatio) {
  const CorpusCase& c = GetParam();
  const InflationResult result = inflate_corpus_mesh(c.file, 200.0, c.material, c.volume_ratio);
  ASSERT_EQ(inflation_stop_word(result.stop), std::string(inflation_stop_word(c.expected))) << c.label << ": " << result.message;
  EXPECT_EQ(result.converged, c.expected == InflationStop::Converged);
  if (c.expected == InflationStop::Converged) {
    EXPECT_NEAR(result.volume_ratio, c.volume_ratio, 1e-6 * c.volume_ratio);
  } else {
    // Where the walls first touch on the way, or at the target (the knot's tube thickens into itself
    // from about x3.3 on, so either is that answer).
    EXPECT_GT(result.volume_ratio, 1.0);
    EXPECT_LE(result.volume_ratio, c.volume_ratio * (1.0 + 1e-6));
  }
  EXPECT_GT(result.pressure_kpa, 0.0);
  EXPECT_TRUE(result.deformed.allFinite());
}

INSTANTIATE_TEST_SUITE_P(
    Corpus, CorpusInflationTest,
    ::testing::Values(CorpusCase{"blobby_silicone", "blobby.off", "silicone", 8.0},
                      CorpusCase{"cactus_latex", "cactus.off", "latex", 27.0},
                      CorpusCase{"spool_neo_hookean", "spool.off", "neo-hookean:mu=0.3", 8.0},
                      CorpusCase{"fandisk_silicone", "fandisk.off", "silicone", 8.0},
                      CorpusCase{"rotor_neo_hookean", "rotor_small.off", "neo-hookean:mu=0.3", 8.0, InflationStop::PassesThroughItself},
                      CorpusCase{"dino_latex", "dino.off", "latex", 27.0},
                      CorpusCase{"knot_silicone", "knot.off", "silicone", 8.0, InflationStop::PassesThroughItself}),
    [](const auto& test_info) { return std::string(test_info.param.label); });

}  // namespace
}  // namespace balloon

namespace balloon {
namespace {

TEST(Inflation, MeshWithAThousandthOfADegreeSliverInflates) {
  TriMesh mesh = test::sphere_with_cap_sliver(50.0, 2, 0.001);
  ASSERT_TRUE(validate_balloon_mesh(mesh).ok());
  EXPECT_LT(min_angle_deg(mesh.vertices, mesh.faces), 0.0011);
  for (const bool tension_field : {false, true})
  for (const char* spec : {"silicone", "latex"}) {
    InflationOptions options;
    options.material = *parse_material_spec(spec);
    options.volume_ratio = 8.0;
    options.tension_field = tension_field;
    const InflationResult result = inflate(mesh, options);
    ASSERT_TRUE(result.converged) << spec << " tension field " << tension_field << ": " << result.message;
    EXPECT_EQ(result.stop, InflationStop::Converged);
    EXPECT_NEAR(result.volume_ratio, 8.0, 1e-6);
    EXPECT_TRUE(result.deformed.allFinite());
    EXPECT_EQ(result.flipped_cap_slivers, 1);
  }
}

TEST(Inflation, MeshWithAThousandthOfADegreeNeedleInflatesAsItIs) {
  // A needle's short edge keeps its direction under any smooth deformation, unlike a cap's height, so
  // it is simulated as it is (no flip).
  TriMesh mesh = test::sphere_with_needle_slivers(50.0, 2, 0.001);
  ASSERT_TRUE(validate_balloon_mesh(mesh).ok());
  EXPECT_LT(min_angle_deg(mesh.vertices, mesh.faces), 0.0011);
  for (const char* spec : {"silicone", "latex"}) {
    InflationOptions options;
    options.material = *parse_material_spec(spec);
    options.volume_ratio = 8.0;
    const InflationResult result = inflate(mesh, options);
    ASSERT_TRUE(result.converged) << spec << ": " << result.message;
    EXPECT_NEAR(result.volume_ratio, 8.0, 1e-6);
    EXPECT_TRUE(result.deformed.allFinite());
    EXPECT_EQ(result.flipped_cap_slivers, 0);
  }
}

TEST(Inflation, TheAnchorInflatesToLowVolumeWithItsCapSliverFlipped) {
  // anchor_dense's 0.0007-degree cap made its constant-strain triangle ~1e5 times stiffer across its long
  // edge than its neighbours: at 20 mm every case to volume ratio 2 ran into the 20 s limit (bench_robustness).
  const InflationResult result = inflate_corpus_mesh("anchor_dense.off", 20.0, "silicone", 2.0);
  expect_converges_within(result, 2.0, 300);
  EXPECT_EQ(result.flipped_cap_slivers, 1);
}

TEST(Inflation, TheLatexCubesDesignedRestShapeDoesNotCreepNearSaddles) {
  // A rest shape our design computed (tests/data/designed/PROVENANCE.md), inflated from rest with latex
  // to x8 as the design's check from rest and balloon simulate do. Near x8 its exact stiffness has one or
  // two unstable modes, and unshifted SQP steps on the projected blocks sat at 1e-4 N (2,000 force
  // tolerances) for 55 steps at a time: 1,805 Newton steps in all. With the exact Hessian, shifted, as the
  // model where they creep: 402.
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/designed/cube_866_latex_rest.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  InflationOptions options;
  options.material = *parse_material_spec("latex");
  options.thickness_mm = 0.5;
  options.volume_ratio = 8.0;
  const InflationResult result = inflate(*mesh, options);
  expect_converges_within(result, 8.0, 900);
}

TEST(Inflation, FlatFacedBoxInflatesFromZeroPressure) {
  // cube_866: flat faces, which have no out-of-plane stiffness at rest, and sharp edges.
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/cube_866.off");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  ASSERT_TRUE(validate_balloon_mesh(*mesh).ok());
  mesh->vertices *= 100.0 / bounding_box_diagonal(mesh->vertices);
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  // Volume control barely off the stress-free state, where the pressure is close to zero.
  options.volume_ratio = 1.01;
  InflationResult result = inflate(*mesh, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.volume_ratio, 1.01, 1e-8);
  EXPECT_GT(result.pressure_kpa, 0.0);
  // Pressure control starts at p = 0 too.
  options.control = InflationControl::Pressure;
  options.pressure_kpa = 0.5 * result.pressure_kpa;
  result = inflate(*mesh, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_GT(result.volume_ratio, 1.0);
  EXPECT_LT(result.volume_ratio, 1.01);
}

TEST(Inflation, PressureFarBelowTheFirstStepsFindsHowFarTheFlatFacesBulge) {
  // 0.001 kPa on the 100 mm cube: the path's first volume step (x1.5) has over a thousand times that
  // pressure, and a flat face's pressure grows as the cube of the added volume, so the equilibrium lies
  // near x1.15, not where a straight line from the rest points (x1.0004, a nearly slack sheet whose
  // solves crept: 254 Newton steps before the bracket interpolated on that power law).
  InflationOptions options;
  options.material = *parse_material_spec("mooney-rivlin:C1=0.18,C2=0.02");
  options.control = InflationControl::Pressure;
  options.pressure_kpa = 0.001;
  const InflationResult result = inflate(corpus_mesh("cube_866.off", 100.0), options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_NEAR(result.pressure_kpa, 0.001, 1e-12);
  EXPECT_GT(result.volume_ratio, 1.1);
  EXPECT_LT(result.volume_ratio, 1.2);
  EXPECT_LE(result.newton_iterations, 150);
}

TEST(Inflation, ALongStepReportsItsNewtonIterationsAsItGoes) {
  // The cube to x8: several volume steps of several Newton iterations each. With no interval, every
  // iteration that goes on is one "newton" event (its index counted over the run), and every step
  // reached one "inflate" event with the shape.
  auto mesh = read_mesh(std::string(BALLOON_TEST_DATA_DIR) + "/meshes/cube_866.off");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  mesh->vertices *= 100.0 / bounding_box_diagonal(mesh->vertices);
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 8.0;
  options.newton_progress_interval_s = 0.0;
  int newton_events = 0, inflate_events = 0, last_iteration = -1;
  bool ordered = true, finite = true, shapes_only_when_reached = true;
  options.progress = [&](const ProgressEvent& event) {
    if (event.phase == "newton") {
      ++newton_events;
      ordered = ordered && event.iteration > last_iteration;
      last_iteration = event.iteration;
      finite = finite && std::isfinite(event.residual_norm) && std::isfinite(event.pressure_kpa);
      shapes_only_when_reached = shapes_only_when_reached && event.shape == nullptr;
    } else if (event.phase == "inflate") {
      ++inflate_events;
      shapes_only_when_reached = shapes_only_when_reached && event.shape != nullptr;
    }
  };
  const InflationResult result = inflate(*mesh, options);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_EQ(newton_events, result.newton_iterations);
  EXPECT_EQ(last_iteration, result.newton_iterations - 1);
  EXPECT_EQ(inflate_events, result.load_steps);
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(finite);
  EXPECT_TRUE(shapes_only_when_reached);

  // The default interval (1 s) lets far fewer through on this fast case.
  options.newton_progress_interval_s = InflationOptions().newton_progress_interval_s;
  newton_events = 0;
  last_iteration = -1;
  inflate(*mesh, options);
  EXPECT_LT(newton_events, result.newton_iterations);
}

TEST(Inflation, ATimeLimitSaysHowFarThePathGot) {
  // A path reaches x2 within its budget, which has run out before it goes on to x8: it stops at once,
  // holding x2, and says so.
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  options.max_time_s = 1.0;
  InflationPath path(corpus_mesh("cube_866.off", 100.0), options);
  ASSERT_TRUE(path.advance(InflationControl::VolumeRatio, 2.0).converged);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const InflationResult result = path.advance(InflationControl::VolumeRatio, 8.0);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.stop, InflationStop::TimeLimit);
  EXPECT_NEAR(result.volume_ratio, 2.0, 1e-6);
  EXPECT_EQ(result.message, "time limit reached at volume ratio 2, on the way to 8");
}

TEST(Inflation, APressureControlledTimeLimitSaysHowFarThePathGot) {
  // As above under pressure control: the path holds x2 and names its pressure, volume and target.
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  options.max_time_s = 1.0;
  InflationPath path(corpus_mesh("cube_866.off", 100.0), options);
  const InflationResult at_two = path.advance(InflationControl::VolumeRatio, 2.0);
  ASSERT_TRUE(at_two.converged);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const double target_kpa = 1.5 * at_two.pressure_kpa;
  const InflationResult result = path.advance(InflationControl::Pressure, target_kpa);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.stop, InflationStop::TimeLimit);
  EXPECT_NEAR(result.volume_ratio, 2.0, 1e-6);
  EXPECT_NEAR(result.pressure_kpa, at_two.pressure_kpa, 1e-9 * at_two.pressure_kpa);
  EXPECT_EQ(result.message, "time limit reached at " + format_kpa(at_two.pressure_kpa * MPA_PER_KPA) +
                                " (volume ratio 2), on the way to " + format_kpa(target_kpa * MPA_PER_KPA));
}

TEST(Inflation, SaysHowMuchOfTheBalloonIsWhereItsRubbersPressureFalls) {
  // Every triangle of an inflated sphere stretches by about cbrt(ratio). Latex's pressure falls between
  // stretch 1.365 and 3.966, silicone's between 1.406 and 1.620: at x8 (stretch 2) latex stands wholly in
  // its band and silicone past it; at x2 (stretch 1.26) latex stands before it.
  const TriMesh sphere = make_icosphere(10.0, 2);
  struct Case {
    const char* material;
    double ratio, share;
  } cases[] = {{"latex", 8.0, 1.0}, {"silicone", 8.0, 0.0}, {"latex", 2.0, 0.0}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.material) + " x" + std::to_string(c.ratio));
    InflationOptions options;
    options.material = *parse_material_spec(c.material);
    options.volume_ratio = c.ratio;
    const InflationResult result = inflate(sphere, options);
    ASSERT_TRUE(result.converged) << result.message;
    ASSERT_TRUE(result.pressure_fall);
    ASSERT_TRUE(result.pressure_fall_area_share);
    EXPECT_NEAR(*result.pressure_fall_area_share, c.share, 1e-12);
  }
  // No equilibrium (a pressure above Neo-Hookean's maximum, about 19 kPa here): the band, no share.
  InflationOptions above;
  above.material = make(MaterialModel::NeoHookean, 0.3);
  above.control = InflationControl::Pressure;
  above.pressure_kpa = 100.0;
  const InflationResult none = inflate(sphere, above);
  ASSERT_FALSE(none.converged) << none.message;
  EXPECT_TRUE(none.pressure_fall);
  EXPECT_FALSE(none.pressure_fall_area_share);
}

TEST(Inflation, TensionFieldChangesNothingOnATautSphere) {
  // A sphere is in equibiaxial tension everywhere: no triangle is relaxed and the law holds as before.
  const TriMesh sphere = make_icosphere(10.0, 2);
  InflationOptions options;
  options.material = *parse_material_spec("latex");
  options.volume_ratio = 8.0;
  options.tension_field = true;
  const InflationResult relaxed = inflate(sphere, options);
  options.tension_field = false;
  const InflationResult plain = inflate(sphere, options);
  ASSERT_TRUE(relaxed.converged && plain.converged) << relaxed.message << " / " << plain.message;
  EXPECT_EQ(relaxed.wrinkled_elements, 0);
  EXPECT_NEAR(relaxed.pressure_kpa, plain.pressure_kpa, 1e-9 * plain.pressure_kpa);
}

TEST(Inflation, BendingKeepsTheSphereLawAndAutoLeavesItOffWhereTheMembraneConverges) {
  // A uniform scaling keeps every dihedral angle, so the bending hinges carry (almost) nothing on a
  // sphere: the closed-form pressure holds with bending on, for all three laws, past their maxima.
  const TriMesh sphere = make_icosphere(10.0, 3);
  const double radius = 3.0 * mesh_volume(sphere) / mesh_area(sphere);
  const double h = 0.5;
  for (const Material& material : {make(MaterialModel::NeoHookean, 0.3), make(MaterialModel::MooneyRivlin, 0.18, 0.02),
                                   make(MaterialModel::HartSmith, 0.1, 3e-4, 1.0)}) {
    InflationOptions options;
    options.material = material;
    options.thickness_mm = h;
    options.volume_ratio = 8.0;
    options.bending = BendingUse::On;
    const InflationResult bent = inflate(sphere, options);
    ASSERT_TRUE(bent.converged) << bent.message;
    EXPECT_TRUE(bent.bending);
    const double expected = sphere_pressure_kpa(material, h, radius, std::cbrt(bent.volume_ratio));
    EXPECT_NEAR(bent.pressure_kpa, expected, 5e-3 * std::abs(expected));
    options.bending = BendingUse::Auto;
    const InflationResult automatic = inflate(sphere, options);
    ASSERT_TRUE(automatic.converged) << automatic.message;
    EXPECT_FALSE(automatic.bending);
    EXPECT_NEAR(bent.pressure_kpa, automatic.pressure_kpa, 1e-3 * automatic.pressure_kpa);
  }
}

TEST(Inflation, AStepThatCreepsThroughWrinklesTriesTheSheetsBendingAtOnce) {
  // The femur (200 mm, silicone) to ratio 2: as a membrane its first volume step creeps through wrinkles
  // (its stiffness indefinite at most factorizations); four resumes took 240 Newton steps before bending
  // went on, 386 in all. Tried with bending after the first failed attempt (60 membrane steps): 81; after
  // its first 20 membrane steps, once they show the creep: 41.
  const InflationResult result = inflate_corpus_mesh("femur.off", 200.0, "silicone", 2.0);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_TRUE(result.bending);
  EXPECT_NEAR(result.volume_ratio, 2.0, 2e-6);
  EXPECT_LT(result.newton_iterations, 60);
}

TEST(Inflation, TheEarlyBentTryGoesOnFromWhereTheMembraneStood) {
  // The blob (200 mm, Neo-Hookean) to x8 in one step: 20 membrane steps creep through wrinkles, then the
  // sheet's bending converges. Started again from the predictor, the bent try took 14 more Newton steps
  // (34 in all); from where the membrane stood, 3 (23).
  const InflationResult result = inflate_corpus_mesh("blobby.off", 200.0, "neo-hookean:mu=0.3", 8.0);
  EXPECT_TRUE(result.bending);
  expect_converges_within(result, 8.0, 28);
}

TEST(Inflation, ShiftedStepsPastAPressureMaximumHandOverToTheExactStep) {
  // The femur at 20 mm with latex to ratio 27 (past latex's pressure maximum): 356 Newton steps, 29 s.
  // Its shifted SQP steps crept at |r| ~ 3e-3 N where the exact step converged in 3 once tried, and its
  // bent path was tried early, dropped, and later run again from the start. With the exact step tried
  // again after each tenfold fall of the residual, and the early bent try's end kept: 112.
  expect_converges_within(inflate_corpus_mesh("femur.off", 20.0, "latex", 27.0), 27.0, 200);
}

TEST(Inflation, PastAPressureMaximumTheExactStepDescendsOnTheAugmentedLagrangian) {
  // The dinosaur (200 mm, Neo-Hookean) to ratio 8, past the law's pressure maximum: its stiffness has a
  // negative pivot that the volume constraint removes. Line-searched on the residual norm there, the exact
  // steps led to a membrane equilibrium that passes through itself; on the augmented Lagrangian, as for a
  // positive definite stiffness, the path reaches one (with the sheet's bending) that does not.
  const InflationResult result = inflate_corpus_mesh("dino.off", 200.0, "neo-hookean:mu=0.3", 8.0);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_EQ(result.stop, InflationStop::Converged);
  EXPECT_NEAR(result.volume_ratio, 8.0, 8.0 * 1e-6);
}

TEST(Inflation, TheSqpShiftOnlyRemovesWhatTheVolumeConstraintLeavesUnstable) {
  // The knot at 20 mm with Neo-Hookean rubber to ratio 8: a bulge runs along the tube at a nearly constant
  // pressure. Its model stiffness there has one negative direction that the volume constraint removes, so
  // shifting it until positive definite (about 0.02 N/mm) made every step along the tube tiny: 1,032
  // Newton steps, 67 s. Shifted only until the KKT inertia is a constrained minimum's: 92. Its answer is
  // that the equilibrium passes through itself (its strands touch).
  const InflationResult result = inflate_corpus_mesh("knot.off", 20.0, "neo-hookean:mu=0.3", 8.0);
  EXPECT_EQ(result.stop, InflationStop::PassesThroughItself) << result.message;
  EXPECT_NEAR(result.volume_ratio, 8.0, 8.0 * 1e-6);
  EXPECT_LT(result.newton_iterations, 300);
}

TEST(Inflation, AfterAStepCutShortTheNextSqpStepStartsShifted) {
  // The femur at 20 mm with Neo-Hookean rubber to ratio 8: its unshifted SQP model, nearly singular along
  // the volume constraint, gave steps of 640 mm that the line search cut to 1/2048, step after step: 436
  // Newton steps, 40 s. Starting the step after one cut short at the raised shift: 108.
  expect_converges_within(inflate_corpus_mesh("femur.off", 20.0, "neo-hookean:mu=0.3", 8.0), 8.0, 200);
}

TEST(Inflation, AMembraneEquilibriumThatPassesThroughItselfIsTriedAgainWithBending) {
  // The dinosaur (200 mm) with latex to ratio 27: as a pure membrane its limbs fold through each other;
  // with the sheet's bending, tried once more from the start, the same volume is reached without.
  const InflationResult result = inflate_corpus_mesh("dino.off", 200.0, "latex", 27.0);
  ASSERT_TRUE(result.converged) << result.message;
  EXPECT_TRUE(result.bending);
  EXPECT_NEAR(result.volume_ratio, 27.0, 27.0 * 1e-6);
}

TEST(Inflation, AFailedEarlyBentTryIsNotRepeatedOnceBendingGoesOn) {
  // The anchor at 10 mm with Neo-Hookean rubber to ratio 8: its first step from rest creeps as a membrane,
  // its early bent try diverges (60 Newton steps), and once bending went on for good the same attempt ran
  // again, step for step the same 60: 217 in all. Now the step is cut at once: 158 (125 with the
  // lengthened SQP steps below).
  expect_converges_within(inflate_corpus_mesh("anchor_dense.off", 10.0, "neo-hookean:mu=0.3", 8.0), 8.0, 190);
}

TEST(Inflation, AStepAlongADirectionSofterThanItsModelIsLengthened) {
  // The anchor at 100 mm with Mooney-Rivlin rubber to ratio 2: with bending on, its walls slide towards each
  // other at a nearly constant pressure, 90 unshifted SQP steps each lowering the merit by more than the
  // model predicted, the residual creeping up from 1e-4 N: 237 Newton steps to the answer that the
  // equilibrium passes through itself. Doubled while the merit falls: 80.
  const InflationResult result =
      inflate_corpus_mesh("anchor_dense.off", 100.0, "mooney-rivlin:C1=0.139679,C2=0.0280028", 2.0);
  ASSERT_EQ(inflation_stop_word(result.stop), std::string("passes_through_itself")) << result.message;
  EXPECT_NEAR(result.volume_ratio, 2.0, 2.0 * 1e-6);
  EXPECT_LT(result.newton_iterations, 150);
}

TEST(Inflation, APathThatStrugglesPastItsWallsTouchingEndsThereWithThatReason) {
  // The knot at 100 mm with silicone to ratio 8: its tube thickens until the turns pass through each
  // other, near ratio 3.5 to 4.5; beyond, the path crept for 100 s and ended "no equilibrium found at
  // volume ratio 7.62 (Newton iteration limit reached)". The equilibrium a hard step reached is now
  // checked, and the path ends with the physical reason (about 30 s). Its first step from the stress-free
  // sheet then crept through 550 of its 840 Newton steps (200 mm: resumed from x8, then halved to 4.5,
  // 2.75 and 1.88); a membrane's step from rest is no longer resumed, and cut to a quarter: 480 in all.
  const InflationResult result = inflate_corpus_mesh("knot.off", 100.0, "silicone", 8.0);
  EXPECT_LT(result.newton_iterations, 600);
  ASSERT_EQ(inflation_stop_word(result.stop), std::string("passes_through_itself")) << result.message;
  EXPECT_FALSE(result.converged);
  EXPECT_LE(result.volume_ratio, 8.0 * (1.0 + 1e-6));
  EXPECT_GT(result.volume_ratio, 2.0);
  EXPECT_NE(result.message.find("passes through itself"), std::string::npos) << result.message;
}

TEST(Inflation, ABalloonFarFromTheOriginInflatesAsItDoesAtTheOrigin) {
  // 1 km away its enclosed volume, summed from the origin, was wrong by more than itself: the path never
  // left volume ratio 1 ("Newton iteration limit reached"). Solved about its own centre, it is the same
  // balloon, handed back where it stands.
  const TriMesh sphere = make_icosphere(20.0, 3);
  InflationOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 4.0;
  const InflationResult at_origin = inflate(sphere, options);
  ASSERT_TRUE(at_origin.converged) << at_origin.message;
  const Eigen::RowVector3d offset(1e6, -1e6, 1e6);
  const TriMesh far{sphere.vertices.rowwise() + offset, sphere.faces};
  const InflationResult moved = inflate(far, options);
  ASSERT_TRUE(moved.converged) << moved.message;
  EXPECT_EQ(moved.newton_iterations, at_origin.newton_iterations);
  EXPECT_NEAR(moved.volume_ratio, 4.0, 1e-8);
  EXPECT_NEAR(moved.pressure_kpa, at_origin.pressure_kpa, 1e-9 * at_origin.pressure_kpa);
  const Positions expected = at_origin.deformed.rowwise() + offset;
  EXPECT_LT((moved.deformed - expected).cwiseAbs().maxCoeff(), 1e-6);

  // A path that goes on from a given shape takes it in the caller's frame too.
  InflationPath path(far, options, &moved.deformed);
  const InflationResult further = path.advance(InflationControl::VolumeRatio, 5.0);
  ASSERT_TRUE(further.converged) << further.message;
  EXPECT_NEAR(further.volume_ratio, 5.0, 1e-8);
  EXPECT_LT((centroid(further.deformed) - centroid(far.vertices)).norm(), 1e-3);
}

}  // namespace
}  // namespace balloon
