// The design driver's steps that the optimizers share: here, switching the sheet's bending on mid-design.
#include <gtest/gtest.h>

#include <algorithm>

#include "design/design_driver.hpp"
#include "design_test_meshes.hpp"

namespace balloon {
namespace {

TEST(DesignDriver, SwitchingBendingOnKeepsAnEquilibriumAndListsTheTerm) {
  const TriMesh target = design_test::inflated_ellipsoid_target(2, 1.0);
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 6.0;
  DesignDriver driver(target, options);
  DesignResult result = driver.begin(DesignMethod::Adjoint);
  const Eigen::VectorXd rest = flat(driver.start().vertices);
  ASSERT_TRUE(driver.inflate_start(rest, result)) << result.message;
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

TEST(DesignDriver, TheAugmentedLagrangianKeepsAMembrane) {
  const TriMesh target = design_test::inflated_ellipsoid_target(2, 1.0);
  DesignOptions options;
  options.material = *parse_material_spec("silicone");
  options.volume_ratio = 6.0;
  options.method = DesignMethod::AugmentedLagrangian;
  DesignDriver driver(target, options);
  DesignResult result = driver.begin(DesignMethod::AugmentedLagrangian);
  const Eigen::VectorXd rest = flat(driver.start().vertices);
  ASSERT_TRUE(driver.inflate_start(rest, result)) << result.message;
  EXPECT_FALSE(driver.switch_bending_on(rest, result)) << "its derivatives are membrane-only";
  EXPECT_FALSE(driver.model().bending());
}

}  // namespace
}  // namespace balloon
