// The design driver's steps that the optimizers share: switching the sheet's bending on mid-design, taking
// the shape reached from rest, judging a trial's start, and going back to the best design.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "design/design_driver.hpp"
#include "design/surface_distance.hpp"
#include "design_test_meshes.hpp"

namespace balloon {
namespace {

/// Silicone to x6 on the smooth ellipsoid every test here starts from.
DesignOptions ellipsoid_options(DesignMethod method) {
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 6.0;
  options.method = method;
  return options;
}

/// A driver on that ellipsoid with its result begun; the driver keeps references to the target and options
/// held here.
struct EllipsoidDesign {
  explicit EllipsoidDesign(DesignMethod method)
      : target(design_test::inflated_ellipsoid_target(2, 1.0)),
        options(ellipsoid_options(method)),
        driver(target, options),
        result(driver.begin(method)),
        start(flat(driver.start().vertices)) {}

  /// Inflates the start rest shape to the target's volume (result.message says why not).
  bool inflate_start() { return driver.inflate_start(start, result); }

  const TriMesh target;
  const DesignOptions options;
  DesignDriver driver;
  DesignResult result;
  const Eigen::VectorXd start;  // the start rest shape
};

TEST(DesignDriver, SwitchingBendingOnKeepsAnEquilibriumAndListsTheTerm) {
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  DesignResult& result = design.result;
  const Eigen::VectorXd& rest = design.start;
  ASSERT_TRUE(design.inflate_start()) << result.message;
  ASSERT_FALSE(driver.model().bending()) << "a smooth ellipsoid inflates as a membrane";
  const Eigen::VectorXd membrane_x = driver.x();

  ASSERT_TRUE(driver.switch_bending_on(rest, result)) << driver.last_report().message;
  EXPECT_TRUE(driver.model().bending());
  EXPECT_EQ(std::count(result.active_terms.begin(), result.active_terms.end(), "sheet_bending"), 1);
  // The new state balances the model with bending, at the target's volume.
  EXPECT_TRUE(driver.last_report().converged);
  EXPECT_NEAR(driver.model().volume(driver.x()), driver.target_volume(), 1e-5 * driver.target_volume());
  // A 0.5 mm sheet on a 60 mm balloon bends little: the shape moves by far less than a millimetre.
  EXPECT_LT((driver.x() - membrane_x).cwiseAbs().maxCoeff(), 0.1);

  EXPECT_FALSE(driver.switch_bending_on(rest, result)) << "once only";
  EXPECT_EQ(std::count(result.active_terms.begin(), result.active_terms.end(), "sheet_bending"), 1);
}

TEST(DesignDriver, SettlingTakesAnEquilibriumShortOfTheToleranceOnToIt) {
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  const Eigen::VectorXd balanced = driver.x();
  const double balanced_pressure = driver.pressure();
  // Moved off its equilibrium by up to a micrometre per coordinate: a state short of the force tolerance,
  // as one Newton's stagnation allowance accepted would be.
  Eigen::VectorXd moved = balanced;
  for (int c = 0; c < moved.size(); ++c) moved[c] += 1e-3 * std::sin(0.7 * c);
  driver.x() = moved;
  Eigen::VectorXd x = moved;
  double pressure = balanced_pressure;
  ASSERT_TRUE(driver.equilibrium(design.start, x, pressure));
  ASSERT_GT(driver.last_report().iterations, 0) << "the moved state is not at the tolerance";

  ASSERT_TRUE(driver.settle(design.start));
  // Settled: Newton from there has nothing left to do, and it is the equilibrium it was moved off.
  x = driver.x();
  pressure = driver.pressure();
  ASSERT_TRUE(driver.equilibrium(design.start, x, pressure));
  EXPECT_EQ(driver.last_report().iterations, 0);
  // (up to a rigid motion, which the moved state's field partly was)
  const Positions aligned = rigid_align_to(unflatten(driver.x()), unflatten(balanced));
  EXPECT_LT((aligned - unflatten(balanced)).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(driver.pressure(), balanced_pressure, 1e-6 * balanced_pressure);
}

TEST(DesignDriver, TheShapeReachedFromRestLeavesTheDesignsAloneAndReplacesAnotherOne) {
  // Past a pressure maximum the design can follow a branch that inflating its rest shape from rest does
  // not reach; the driver then goes on from the shape that inflation reaches.
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  const Eigen::VectorXd start_x = driver.x();
  const double start_pressure = driver.pressure();
  EXPECT_FALSE(driver.shape_from_rest_pending());
  Eigen::VectorXd rest = design.start;
  EXPECT_FALSE(driver.take_pending_shape_from_rest(rest)) << "no check was started";

  // Silicone here has one equilibrium per volume: from rest it reaches the driver's own shape.
  driver.start_shape_from_rest(rest, 1);
  EXPECT_TRUE(driver.shape_from_rest_pending());
  EXPECT_FALSE(driver.take_pending_shape_from_rest(rest));
  EXPECT_FALSE(driver.shape_from_rest_pending());
  EXPECT_EQ(driver.x(), start_x);
  EXPECT_EQ(rest, design.start);

  // On the target itself (no error, but no equilibrium of this rest shape) the shape reached from rest is
  // another one: the start's inflation again, placed on the target, and the best design seen is forgotten.
  // The check runs while the design goes on; its verdict concerns the rest shape it started from, to which
  // the design goes back.
  driver.x() = flat(design.target.vertices);
  driver.start_shape_from_rest(rest, 1);
  Eigen::VectorXd moved_on = 1.01 * rest;
  driver.x() = 1.01 * start_x;
  ASSERT_TRUE(driver.take_pending_shape_from_rest(moved_on));
  EXPECT_EQ(moved_on, design.start);
  EXPECT_LT((driver.x() - start_x).cwiseAbs().maxCoeff(), 1e-3);  // mm, on a 65 mm balloon
  EXPECT_NEAR(driver.pressure(), start_pressure, 1e-6 * start_pressure);
  Eigen::VectorXd best = rest;
  EXPECT_FALSE(driver.restore_best_equilibrium(best)) << "the best design seen belonged to the other shape";
}

TEST(DesignDriver, TheClosestShapeFromRestIsTheStartUntilACheckFromRestComesCloser) {
  // The start's inflation is the forward solver's path from rest, so the start is the first rest shape
  // checked from rest; the result carries it for the hand-back of closest_from_rest.hpp.
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  Eigen::VectorXd rest = design.start;
  driver.finish(design.result, rest);
  ASSERT_TRUE(design.result.closest_from_rest && design.result.baseline_avg_error_mm);
  EXPECT_EQ(design.result.closest_from_rest->iteration, 0);
  EXPECT_EQ(design.result.closest_from_rest->avg_error_mm, *design.result.baseline_avg_error_mm);
  EXPECT_EQ(design.result.closest_from_rest->rest, design.driver.start().vertices);

  // The known answer (the ellipsoid the target was inflated from), checked from rest at iteration 7,
  // reaches the target itself: it becomes the closest, whichever shape the design then goes on from.
  EllipsoidDesign again(DesignMethod::Adjoint);
  ASSERT_TRUE(again.inflate_start()) << again.result.message;
  TriMesh known = design_test::make_icosphere(2, 20.0);
  known.vertices.col(0) *= 1.6;
  rest = again.start;
  again.driver.start_shape_from_rest(flat(known.vertices), 7);
  again.driver.take_pending_shape_from_rest(rest);
  again.driver.finish(again.result, rest);
  ASSERT_TRUE(again.result.closest_from_rest);
  EXPECT_EQ(again.result.closest_from_rest->iteration, 7);
  EXPECT_LT(again.result.closest_from_rest->avg_error_mm, 1e-4);  // mm, on a 65 mm balloon
  EXPECT_EQ(again.result.closest_from_rest->rest, known.vertices);
}

TEST(DesignDriver, WhereACheckFromRestFindsAnotherShapeTheIteratesBeforeItAreCheckedToo) {
  // Iteration 1's rest shape is the known answer, whose shape from rest is the target, as its design's
  // is. Iteration 2 goes back to the start but, as on a branch inflation from rest does not reach, its
  // design's shape is the target too: its check, started at iteration 2 as at a growth, finds another
  // shape (the start's, 1.4 mm away on average). Iteration 1, which the check passed over, is then
  // checked as well and becomes the closest candidate.
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  TriMesh known = design_test::make_icosphere(2, 20.0);
  known.vertices.col(0) *= 1.6;
  const Eigen::VectorXd known_rest = flat(known.vertices);
  driver.x() = flat(design.target.vertices);
  SurfaceDistanceStats on_target;  // the design's own error on its branch: none
  driver.record(design.result, 1, on_target, known_rest);
  driver.record(design.result, 2, on_target, design.start);
  driver.start_shape_from_rest(design.start, 2);
  Eigen::VectorXd rest = design.start;
  EXPECT_TRUE(driver.take_pending_shape_from_rest(rest)) << "iteration 2 reaches another shape from rest";
  driver.finish(design.result, rest);
  ASSERT_TRUE(design.result.closest_from_rest);
  EXPECT_EQ(design.result.closest_from_rest->iteration, 1);
  EXPECT_LT(design.result.closest_from_rest->avg_error_mm, 1e-4);  // mm, on a 65 mm balloon
  EXPECT_EQ(design.result.closest_from_rest->rest, known.vertices);

  // Where the check reaches the design's own shape (the start's, from the start), the iterates before it
  // are not inflated: the known answer recorded at iteration 1 never becomes a candidate.
  EllipsoidDesign agreeing(DesignMethod::Adjoint);
  ASSERT_TRUE(agreeing.inflate_start()) << agreeing.result.message;
  agreeing.driver.record(agreeing.result, 1, on_target, known_rest);
  agreeing.driver.start_shape_from_rest(agreeing.start, 2);
  rest = agreeing.start;
  EXPECT_FALSE(agreeing.driver.take_pending_shape_from_rest(rest));
  agreeing.driver.finish(agreeing.result, rest);
  ASSERT_TRUE(agreeing.result.closest_from_rest && agreeing.result.baseline_avg_error_mm);
  EXPECT_NE(agreeing.result.closest_from_rest->iteration, 1);
  EXPECT_NEAR(agreeing.result.closest_from_rest->avg_error_mm, *agreeing.result.baseline_avg_error_mm, 1e-6);
}

TEST(DesignDriver, AShapeFromRestThatPassesThroughItselfIsNoCandidate) {
  // The target with one vertex pushed through the opposite wall: 0.1 mm from the target on average, far
  // closer than the start's shape from rest, but no balloon a maker gets; the start stays the candidate.
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  Positions folded = design.target.vertices;
  const Eigen::Index top = [&] { Eigen::Index v; folded.col(2).maxCoeff(&v); return v; }();
  folded(top, 2) = folded.col(2).minCoeff() - 5.0;
  driver.remember_if_closest_from_rest(flat(design.target.vertices), folded, 3);
  Eigen::VectorXd rest = design.start;
  driver.finish(design.result, rest);
  ASSERT_TRUE(design.result.closest_from_rest && design.result.baseline_avg_error_mm);
  EXPECT_EQ(design.result.closest_from_rest->iteration, 0);

  // The same shape without the fold is one.
  EllipsoidDesign again(DesignMethod::Adjoint);
  ASSERT_TRUE(again.inflate_start()) << again.result.message;
  again.driver.remember_if_closest_from_rest(flat(again.target.vertices), again.target.vertices, 3);
  rest = again.start;
  again.driver.finish(again.result, rest);
  ASSERT_TRUE(again.result.closest_from_rest);
  EXPECT_EQ(again.result.closest_from_rest->iteration, 3);
}

TEST(DesignDriver, ACheckFromRestStillRunningWhenTheDesignEndsIsAbandoned) {
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  driver.x() = flat(design.target.vertices);  // a check would switch, were it taken
  driver.start_shape_from_rest(design.start, 1);
  driver.finish(design.result, design.start);
  EXPECT_FALSE(driver.shape_from_rest_pending());
  Eigen::VectorXd rest = design.start;
  EXPECT_FALSE(driver.take_pending_shape_from_rest(rest));
  EXPECT_EQ(driver.x(), flat(design.target.vertices));
}

TEST(DesignDriver, ATrialStartFarPastTheLinearRangeIsNotWorthNewtonSteps) {
  // A first-order predictor carried far past the linear range puts a stiffening rubber into its
  // exponential: such trials started at 1e20-1e89 times the force scale and spent 30 Newton steps each
  // without converging.
  EllipsoidDesign design(DesignMethod::Adjoint);
  DesignDriver& driver = design.driver;
  const Eigen::VectorXd& rest = design.start;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  const Eigen::VectorXd x = driver.x();
  const double pressure = driver.pressure();

  EXPECT_TRUE(driver.trial_start_in_range(rest, x, pressure)) << "the equilibrium itself";
  // An ordinary trial: every rest vertex moved by 1% of the rest shape's size, the inflated shape kept.
  EXPECT_TRUE(driver.trial_start_in_range(1.01 * rest, x, pressure));
  // The same inflated shape over a rest shape a quarter the size: Hart-Smith's exponential at 4x the stretch.
  EXPECT_FALSE(driver.trial_start_in_range(0.25 * rest, x, pressure));
  Eigen::VectorXd broken = x;
  broken[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(driver.trial_start_in_range(rest, broken, pressure));
}

TEST(DesignDriver, TheAugmentedLagrangianKeepsAMembrane) {
  EllipsoidDesign design(DesignMethod::AugmentedLagrangian);
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  EXPECT_FALSE(design.driver.switch_bending_on(design.start, design.result)) << "its derivatives are membrane-only";
  EXPECT_FALSE(design.driver.model().bending());
}

TEST(DesignDriver, RestoreBestHandsBackTheStartWhenTheCurrentShapeIsFartherFromTheTarget) {
  // What both optimizers end with: the augmented Lagrangian's final equilibrium can inflate farther from
  // the target than its start (cactus, latex, 10 s: 3.22 mm against 3.10 mm); the start comes back then.
  EllipsoidDesign design(DesignMethod::AugmentedLagrangian);
  DesignDriver& driver = design.driver;
  const Eigen::VectorXd& start = design.start;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  const Eigen::VectorXd start_x = driver.x();

  Eigen::VectorXd rest = start;
  EXPECT_FALSE(driver.restore_best(rest)) << "the start itself is no worse than the best";
  rest = 1.01 * start;
  driver.x() = 1.05 * start_x;  // an inflated shape 5% too large: farther from the target
  EXPECT_TRUE(driver.restore_best(rest));
  EXPECT_EQ(rest, start);
  EXPECT_EQ(driver.x(), start_x);
}

TEST(DesignDriver, RestoreBestEquilibriumHandsBackTheStartEvenWhereTheCurrentShapeLooksCloser) {
  // The augmented Lagrangian's final inflation may find no equilibrium: whatever its unbalanced shape's
  // error, the start (a true equilibrium) comes back.
  EllipsoidDesign design(DesignMethod::AugmentedLagrangian);
  DesignDriver& driver = design.driver;
  Eigen::VectorXd rest = design.start;
  EXPECT_FALSE(driver.restore_best_equilibrium(rest)) << "nothing recorded before the start is inflated";
  const Eigen::VectorXd& start = design.start;
  ASSERT_TRUE(design.inflate_start()) << design.result.message;
  const Eigen::VectorXd start_x = driver.x();
  const double start_pressure = driver.pressure();

  rest = 1.01 * start;
  driver.x() = flat(design.target.vertices);  // on the target itself: closer than any equilibrium, but unbalanced
  EXPECT_FALSE(driver.restore_best(rest)) << "restore_best keeps a closer shape";
  EXPECT_TRUE(driver.restore_best_equilibrium(rest));
  EXPECT_EQ(rest, start);
  EXPECT_EQ(driver.x(), start_x);
  EXPECT_EQ(driver.pressure(), start_pressure);
}

}  // namespace
}  // namespace balloon
