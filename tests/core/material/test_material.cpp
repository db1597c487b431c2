#include "material/material.hpp"

#include <gtest/gtest.h>

#include <string>

namespace balloon {
namespace {

std::string problem_of(const std::string& spec) {
  const Result<Material> material = parse_material_spec(spec);
  return material ? material_problem(*material) : material.error();
}

TEST(Material, ModuliOutsideAnyRubbersAreRefusedWithTheRange) {
  // Real rubbers and gels: kPa to tens of MPa. At 1e-300 MPa every force rounded to 0 and a simulation was
  // "converged" after 0 Newton steps; at 1e300 the first residual overflowed.
  EXPECT_EQ(problem_of("neo-hookean:mu=0.3"), "");
  EXPECT_EQ(problem_of("neo-hookean:mu=1e-6"), "");
  EXPECT_EQ(problem_of("mooney-rivlin:C1=0.14,C2=0"), "") << "a second modulus may vanish";
  EXPECT_EQ(problem_of("mooney-rivlin:C1=0.14,C2=1e-12"), "") << "a fit drives an unneeded C2 towards 0";
  for (const char* spec : {"neo-hookean:mu=1e-300", "neo-hookean:mu=1e300", "hart-smith:G=1e-7,k1=3e-4,k2=1",
                           "mooney-rivlin:C1=0.14,C2=1e6"}) {
    const std::string problem = problem_of(spec);
    EXPECT_NE(problem.find("100 GPa"), std::string::npos) << spec << ": " << problem;
  }
  EXPECT_NE(problem_of("neo-hookean:mu=1e-300").find("mu must be a modulus from 1e-06 to 100000 MPa"),
            std::string::npos);
  // Hart-Smith's k1: up to 100 (k1 = 10 overflows only on the way to x27, which the inflation names);
  // 1e300 overflowed at the rest shape itself.
  EXPECT_EQ(problem_of("hart-smith:G=0.1,k1=10,k2=1"), "");
  EXPECT_NE(problem_of("hart-smith:G=0.1,k1=1e300,k2=1").find("k1 must be from 0 to 100"), std::string::npos);
}

}  // namespace
}  // namespace balloon
