#include <gtest/gtest.h>

#include "design/balloon_design.hpp"
#include "material/material.hpp"
#include "material/thin_sheet.hpp"
#include "mesh/icosphere.hpp"
#include "mesh/mesh_geometry.hpp"
#include "solve/inflation.hpp"

namespace balloon {
namespace {

TEST(ThinSheet, IssueTensSmallestBalloonIsThinAndAUnitScaleMeshIsNot) {
  // Issue 10's smallest balloon (10 mm across, 0.5 mm) sits at half the limit; the limit itself passes.
  EXPECT_EQ(thin_sheet_problem(0.5, 10.0), "");
  EXPECT_EQ(thin_sheet_problem(0.5, 0.5 / MAX_THICKNESS_PER_DIAGONAL), "");
  // A 10 mm design target at x8 starts at 5 mm, exactly at the limit; remeshed to 1,500 vertices its start
  // is 4.99 mm across (10.02%), which must still pass. 10.3% does not.
  EXPECT_EQ(thin_sheet_problem(0.5, 4.99), "");
  EXPECT_NE(thin_sheet_problem(0.5, 0.5 / 0.103), "");
  // A mesh in unit coordinates (the 37k bunny is 1.6 units across) read as mm: refused, with the fix.
  const std::string bunny = thin_sheet_problem(0.5, 1.6);
  EXPECT_NE(bunny.find("31.2%"), std::string::npos) << bunny;
  EXPECT_NE(bunny.find("--thickness"), std::string::npos) << bunny;
  EXPECT_NE(thin_sheet_problem(1e308, 10.0).find("far thicker"), std::string::npos);
}

TEST(ThinSheet, InflationAndDesignRefuseAThickSheetBeforeAnyWork) {
  const TriMesh sphere = make_icosphere(1.0, 2);  // about 2 mm across
  InflationOptions inflation;
  inflation.material = *parse_material_spec("silicone");
  inflation.volume_ratio = 8.0;
  const InflationResult inflated = inflate(sphere, inflation);
  EXPECT_FALSE(inflated.converged);
  EXPECT_EQ(inflated.stop, InflationStop::InvalidInput);
  EXPECT_EQ(inflated.newton_iterations, 0);
  EXPECT_NE(inflated.message.find("thin-sheet model"), std::string::npos) << inflated.message;

  DesignOptions design;
  design.material = inflation.material;
  const DesignResult designed = design_balloon(sphere, design);
  EXPECT_EQ(designed.stop, DesignStop::StartFailed);
  EXPECT_FALSE(designed.avg_error_mm.has_value());
  EXPECT_NE(designed.message.find("thin-sheet model"), std::string::npos) << designed.message;

  // Ten times larger, the same sheet is thin and inflates.
  TriMesh larger = sphere;
  larger.vertices *= 10.0;
  EXPECT_TRUE(inflate(larger, inflation).converged);
}

}  // namespace
}  // namespace balloon
