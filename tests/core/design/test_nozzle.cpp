#include "design/nozzle.hpp"

#include <gtest/gtest.h>

#include "core/design/design_test_meshes.hpp"

namespace balloon {
namespace {

TEST(Nozzle, ParsesAutoAndCoordinates) {
  auto a = parse_nozzle(" AUTO ");
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE(a->automatic);

  auto p = parse_nozzle("1.5, -2,+3e1");
  ASSERT_TRUE(p.ok()) << p.error();
  EXPECT_FALSE(p->automatic);
  EXPECT_EQ(p->center, Eigen::Vector3d(1.5, -2.0, 30.0));
  EXPECT_EQ(p->radius_mm, 0.0);

  auto r = parse_nozzle("0,0,-50,4.5");
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->radius_mm, 4.5);

  for (const char* bad : {"", "1,2", "1,2,3,4,5", "1,2,x", "1,2,3,", "1,2,3,0", "1,2,3,-1", "nan,0,0", "1,2,3,inf"}) {
    auto result = parse_nozzle(bad);
    EXPECT_FALSE(result.ok()) << "'" << bad << "' was accepted";
    if (!result.ok()) {
      EXPECT_FALSE(result.error().empty());
    }
  }
}

TEST(Nozzle, AutoSelectsTheLowestCapOfASphere) {
  const double radius = 50.0;
  const TriMesh sphere = design_test::make_icosphere(4, radius);
  NozzleSpec spec;
  spec.automatic = true;
  auto selection = select_nozzle(sphere, spec);
  ASSERT_TRUE(selection.ok()) << selection.error();
  EXPECT_NEAR(selection->center.z(), -radius, 1e-9);
  const double diag = 2.0 * radius * std::sqrt(3.0);
  EXPECT_NEAR(selection->radius_mm, 0.05 * diag, 1e-9);
  EXPECT_NEAR(selection->axis.z(), -1.0, 1e-3);
  // Every selected vertex is within the radius (or on the one-ring); the count matches the cap area
  // ratio pi r^2 / (4 pi R^2) of 2562 vertices within a factor of 1.5.
  const double expected = 2562.0 * (selection->radius_mm * selection->radius_mm) / (4.0 * radius * radius);
  EXPECT_GT(static_cast<double>(selection->vertices.size()), expected / 1.5);
  EXPECT_LT(static_cast<double>(selection->vertices.size()), expected * 1.5);
  for (const int v : selection->vertices) {
    EXPECT_LE((sphere.vertices.row(v).transpose() - selection->center).norm(), selection->radius_mm + 1e-9);
  }
  EXPECT_TRUE(std::is_sorted(selection->vertices.begin(), selection->vertices.end()));
}

TEST(Nozzle, TinyRadiusStillHoldsTheOneRing) {
  const TriMesh sphere = design_test::make_icosphere(3, 10.0);
  NozzleSpec spec;
  spec.center = Eigen::Vector3d(0, 0, 10.2);
  spec.radius_mm = 1e-3;
  auto selection = select_nozzle(sphere, spec);
  ASSERT_TRUE(selection.ok()) << selection.error();
  EXPECT_GE(selection->vertices.size(), 6u);  // the closest vertex and its 5 or 6 neighbours
  EXPECT_LE(selection->vertices.size(), 7u);
  EXPECT_NEAR(selection->axis.z(), 1.0, 1e-3);
}

TEST(Nozzle, RejectsACentreFarFromTheSurface) {
  const TriMesh sphere = design_test::make_icosphere(2, 10.0);
  NozzleSpec spec;
  spec.center = Eigen::Vector3d(0, 0, 100.0);
  auto selection = select_nozzle(sphere, spec);
  ASSERT_FALSE(selection.ok());
  EXPECT_NE(selection.error().find("from the nearest surface vertex"), std::string::npos) << selection.error();
}

}  // namespace
}  // namespace balloon
