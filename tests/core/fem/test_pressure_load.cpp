// Finite-difference checks of the pressure load, and its link to the paper's area-weighted normals.
#include <gtest/gtest.h>

#include <random>

#include "core/central_differences.hpp"
#include "fem/pressure_load.hpp"

namespace balloon::fem {
namespace {

TEST(PressureLoad, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 5; ++trial) {
    Vector9d x;
    for (int i = 0; i < 9; ++i) x[i] = u(rng);
    const Vector9d g = triangle_volume_gradient(x);
    const Matrix9d h = triangle_volume_hessian(x);
    const double step = 1e-6;
    const Vector9d g_fd = test::central_difference_gradient(
        [](const Vector9d& y) { return triangle_signed_volume(y); }, x, step);
    const Matrix9d h_fd = test::central_difference_jacobian(
        [](const Vector9d& y) { return triangle_volume_gradient(y); }, x, step);
    ASSERT_GT(g.norm(), 1e-6);
    ASSERT_GT(h.norm(), 1e-6);
    EXPECT_LT((g - g_fd).norm(), 1e-8 * g.norm());
    EXPECT_LT((h - h_fd).norm(), 1e-8 * h.norm());
    EXPECT_LT((h - h.transpose()).norm(), 1e-14);
  }
}

TEST(PressureLoad, GradientSummedOverATriangleIsAreaWeightedNormal) {
  // Summed over the corners, grad V = A n / 3: on a closed one-ring, each vertex gets a third of the
  // area-weighted normals of its triangles (eq. 13 with w = 1/3).
  Vector9d x;
  x << 0.3, -0.2, 1.0, 2.0, 0.1, 0.7, 0.5, 1.9, -0.4;
  const Vector9d g = triangle_volume_gradient(x);
  const Eigen::Vector3d e1 = x.segment<3>(3) - x.segment<3>(0), e2 = x.segment<3>(6) - x.segment<3>(0);
  const Eigen::Vector3d area_normal = 0.5 * e1.cross(e2);
  const Eigen::Vector3d sum = g.segment<3>(0) + g.segment<3>(3) + g.segment<3>(6);
  EXPECT_LT((sum - area_normal / 3.0).norm(), 1e-12);
}

}  // namespace
}  // namespace balloon::fem
