#include "design/trust_radius.hpp"

#include <gtest/gtest.h>

namespace balloon {
namespace {

TEST(GaussNewtonModelDecrease, IsTheQuadraticModelOfAConjugateGradientIterate) {
  // m(t) = t g.d + t^2 d.A.d / 2 with d.A.d = -g.d: g.d = -4 gives a decrease of 4 (t - t^2 / 2).
  EXPECT_DOUBLE_EQ(gauss_newton_model_decrease(1.0, -4.0), 2.0);
  EXPECT_DOUBLE_EQ(gauss_newton_model_decrease(0.5, -4.0), 1.5);
}

TEST(TrustRadius, ACutStepShrinksItByTheCut) {
  TrustRadius trust(3.0);
  trust.after_step(0.4, 0.1, 10.0, 1.0, true);  // halved twice
  EXPECT_DOUBLE_EQ(trust.radius(), 0.75);
}

TEST(TrustRadius, AnUncutStepGrowsItOnlyWhenTheModelAgreed) {
  TrustRadius trust(3.0);
  trust.after_step(0.4, 0.1, 10.0, 1.0, true);
  trust.after_step(0.075, 0.075, 10.0, 0.9, true);  // good agreement: doubled
  EXPECT_DOUBLE_EQ(trust.radius(), 1.5);
  trust.after_step(0.15, 0.15, 10.0, 0.5, true);  // fair agreement: kept
  EXPECT_DOUBLE_EQ(trust.radius(), 1.5);
  trust.after_step(0.15, 0.15, 10.0, 0.1, true);  // poor agreement: half the 1.5 mm move made
  EXPECT_DOUBLE_EQ(trust.radius(), 0.75);
  trust.after_step(1.0, 1.0, 0.5, 0.1, true);  // a full Gauss-Newton step of 0.5 mm that disagreed
  EXPECT_DOUBLE_EQ(trust.radius(), 0.25);
  for (int k = 0; k < 10; ++k) trust.after_step(1.0, 1.0, 0.1, 1.0, true);
  EXPECT_DOUBLE_EQ(trust.radius(), 3.0) << "never past its largest";
}

TEST(TrustRadius, AShortStepThatDisagreedShrinksItAtMostFourfold) {
  // The latex cactus near a fold: a Gauss-Newton direction of 7e-5 mm inside a 0.05 mm radius disagreed
  // with its model; half that move as the radius cost ten iterations of doubling it back.
  TrustRadius trust(0.05);
  trust.after_step(1.0, 1.0, 7e-5, 0.2, true);
  EXPECT_DOUBLE_EQ(trust.radius(), 0.0125);
}

TEST(TrustRadius, StartingOverForgetsWhatItLearned) {
  TrustRadius trust(3.0);
  trust.after_step(1.0, 1.0 / 128.0, 10.0, 1.0, true);  // seven halvings
  trust.start_over();
  EXPECT_DOUBLE_EQ(trust.radius(), 3.0);
}

TEST(TrustRadius, StepsWithoutAModelGrowItWhenUncut) {
  TrustRadius trust(3.0);
  trust.after_step(0.5, 0.25, 10.0, 1.0, false);
  trust.after_step(0.15, 0.15, 10.0, 0.01, false);  // an L-BFGS step: no model to disagree with
  EXPECT_DOUBLE_EQ(trust.radius(), 3.0);
}

}  // namespace
}  // namespace balloon
