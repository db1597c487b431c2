#include "fem/pressure_load.hpp"

namespace balloon::fem {
namespace {

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

double triangle_signed_volume(const Vector9d& x) {
  return x.segment<3>(0).dot(x.segment<3>(3).cross(x.segment<3>(6))) / 6.0;
}

Vector9d triangle_volume_gradient(const Vector9d& x) {
  const Eigen::Vector3d x1 = x.segment<3>(0), x2 = x.segment<3>(3), x3 = x.segment<3>(6);
  Vector9d g;
  g << x2.cross(x3), x3.cross(x1), x1.cross(x2);
  return g / 6.0;
}

Matrix9d triangle_volume_hessian(const Vector9d& x) {
  const Eigen::Vector3d x1 = x.segment<3>(0), x2 = x.segment<3>(3), x3 = x.segment<3>(6);
  // d(x2 x x3)/dx2 = -[x3]x, d(x2 x x3)/dx3 = [x2]x, and cyclically.
  Matrix9d h = Matrix9d::Zero();
  h.block<3, 3>(0, 3) = -cross_matrix(x3);
  h.block<3, 3>(0, 6) = cross_matrix(x2);
  h.block<3, 3>(3, 6) = -cross_matrix(x1);
  h.block<3, 3>(3, 0) = h.block<3, 3>(0, 3).transpose();
  h.block<3, 3>(6, 0) = h.block<3, 3>(0, 6).transpose();
  h.block<3, 3>(6, 3) = h.block<3, 3>(3, 6).transpose();
  return h / 6.0;
}

}  // namespace balloon::fem
