#include "design/rest_triangle_quality.hpp"

#include <cmath>
#include <limits>

#include "fem/membrane_element.hpp"

namespace balloon {

RestTriangleQuality::RestTriangleQuality(const Positions& start, const Faces& faces, double weight)
    : m_faces(faces), m_inverse_metric(faces.rows(), 3), m_start_area(faces.rows()), m_face_weight(faces.rows()) {
  double total_area = 0.0;
  for (int f = 0; f < faces.rows(); ++f) {
    fem::Vector9d corners;
    for (int k = 0; k < 3; ++k) corners.segment<3>(3 * k) = start.row(faces(f, k)).transpose();
    const fem::RestTriangle metric = fem::make_rest_triangle(corners);  // G_start and the area
    const double g11 = metric.m11, g12 = metric.m12, g22 = metric.m22;
    const double determinant = g11 * g22 - g12 * g12;  // (2 A)^2
    m_start_area[f] = metric.area;
    m_inverse_metric.row(f) << g22 / determinant, -g12 / determinant, g11 / determinant;
    // A start triangle with no area has no shape to keep.
    if (determinant > 1e-12 * (g11 + g22) * (g11 + g22) && m_inverse_metric.row(f).allFinite()) {
      m_used_faces.push_back(f);
      total_area += m_start_area[f];
    }
  }
  m_face_weight = weight * m_start_area / std::max(total_area, std::numeric_limits<double>::min());
}

double RestTriangleQuality::distortion_and_gradient(const Eigen::VectorXd& rest, int face,
                                                    Eigen::Matrix<double, 9, 1>* gradient) const {
  const Eigen::Vector3d a = rest.segment<3>(3 * m_faces(face, 0));
  const Eigen::Vector3d e1 = rest.segment<3>(3 * m_faces(face, 1)) - a;
  const Eigen::Vector3d e2 = rest.segment<3>(3 * m_faces(face, 2)) - a;
  const double h11 = m_inverse_metric(face, 0), h12 = m_inverse_metric(face, 1), h22 = m_inverse_metric(face, 2);
  // tr(G_start^-1 G_rest) and the rest area.
  const double trace = h11 * e1.dot(e1) + 2.0 * h12 * e1.dot(e2) + h22 * e2.dot(e2);
  const Eigen::Vector3d normal = e1.cross(e2);
  const double area = 0.5 * normal.norm();
  if (!(area > 0.0)) return std::numeric_limits<double>::infinity();
  const double ratio = m_start_area[face] / (2.0 * area);
  const double distortion = trace * ratio - 1.0;
  if (gradient) {
    const Eigen::Vector3d unit = normal / normal.norm();
    const Eigen::Vector3d d_trace_1 = 2.0 * (h11 * e1 + h12 * e2), d_trace_2 = 2.0 * (h12 * e1 + h22 * e2);
    const Eigen::Vector3d d_area_1 = 0.5 * e2.cross(unit), d_area_2 = 0.5 * unit.cross(e1);
    const Eigen::Vector3d d1 = ratio * d_trace_1 - (trace * ratio / area) * d_area_1;
    const Eigen::Vector3d d2 = ratio * d_trace_2 - (trace * ratio / area) * d_area_2;
    gradient->segment<3>(0) = -(d1 + d2);
    gradient->segment<3>(3) = d1;
    gradient->segment<3>(6) = d2;
  }
  return distortion;
}

double RestTriangleQuality::distortion(const Eigen::VectorXd& rest, int face) const {
  return distortion_and_gradient(rest, face, nullptr);
}

double RestTriangleQuality::value(const Eigen::VectorXd& rest) const {
  double value = 0.0;
  for (int f : m_used_faces) {
    const double excess = distortion_and_gradient(rest, f, nullptr) - THRESHOLD;
    if (excess > 0.0) value += m_face_weight[f] * excess * excess;
  }
  return value;
}

void RestTriangleQuality::add_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const {
  Eigen::Matrix<double, 9, 1> corner_gradient;
  for (int f : m_used_faces) {
    const double excess = distortion_and_gradient(rest, f, &corner_gradient) - THRESHOLD;
    if (!(excess > 0.0) || !std::isfinite(excess)) continue;  // a flat triangle's value is infinite already
    for (int k = 0; k < 3; ++k)
      gradient.segment<3>(3 * m_faces(f, k)) += 2.0 * m_face_weight[f] * excess * corner_gradient.segment<3>(3 * k);
  }
}

Eigen::VectorXd RestTriangleQuality::gauss_newton_times(const Eigen::VectorXd& rest,
                                                        const Eigen::VectorXd& direction) const {
  Eigen::VectorXd product = Eigen::VectorXd::Zero(rest.size());
  Eigen::Matrix<double, 9, 1> corner_gradient;
  for (int f : m_used_faces) {
    const double excess = distortion_and_gradient(rest, f, &corner_gradient) - THRESHOLD;
    if (!(excess > 0.0) || !std::isfinite(excess)) continue;  // a flat triangle's value is infinite already
    double along = 0.0;
    for (int k = 0; k < 3; ++k) along += corner_gradient.segment<3>(3 * k).dot(direction.segment<3>(3 * m_faces(f, k)));
    for (int k = 0; k < 3; ++k)
      product.segment<3>(3 * m_faces(f, k)) += 2.0 * m_face_weight[f] * along * corner_gradient.segment<3>(3 * k);
  }
  return product;
}

int RestTriangleQuality::distorted_count(const Eigen::VectorXd& rest) const {
  int count = 0;
  for (int f : m_used_faces)
    if (distortion_and_gradient(rest, f, nullptr) > THRESHOLD) ++count;
  return count;
}

}  // namespace balloon
