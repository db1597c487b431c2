#include "fem/balloon_model.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fem/pressure_load.hpp"

namespace balloon::fem {

BalloonModel::BalloonModel(const TriMesh& rest, const Material& material, std::vector<double> element_thickness)
    : m_faces(rest.faces), m_material(material), m_thickness(std::move(element_thickness)) {
  if (static_cast<int>(m_thickness.size()) != rest.face_count())
    throw std::invalid_argument("BalloonModel: one thickness per triangle expected");
  set_rest_positions(rest.vertices);
}

void BalloonModel::set_rest_positions(const Positions& rest) {
  m_rest = rest;
  m_rest_triangles.resize(static_cast<size_t>(m_faces.rows()));
  m_rest_area = 0.0;
  // One flat copy: corners() takes a VectorXd, and a Map passed to it would be copied whole for every face
  // (quadratic: 11 s at 100k vertices).
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(m_rest.data(), m_rest.size());
  for (int f = 0; f < m_faces.rows(); ++f) {
    m_rest_triangles[static_cast<size_t>(f)] = make_rest_triangle(corners(x, f));
    m_rest_area += m_rest_triangles[static_cast<size_t>(f)].area;
  }
  if (m_bending) update_rest_hinges();
}

void BalloonModel::set_bending(bool on) {
  m_bending = on;
  std::vector<std::array<int, 2>> hinge_faces;
  m_hinges = on ? mesh_hinges(m_faces, &hinge_faces) : std::vector<HingeVertices>{};
  m_hinge_modulus.clear();
  m_rest_hinges.clear();
  if (!on) return;
  // Per hinge, the bending modulus of the mean thickness of its two triangles, with the small-strain G.
  for (const auto& [a, b] : hinge_faces) {
    const double thickness = 0.5 * (m_thickness[static_cast<size_t>(a)] + m_thickness[static_cast<size_t>(b)]);
    m_hinge_modulus.push_back(bending_modulus(m_material.shear_modulus(), thickness));
  }
  update_rest_hinges();
}

void BalloonModel::update_rest_hinges() {
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(m_rest.data(), m_rest.size());
  m_rest_hinges.resize(m_hinges.size());
  for (size_t h = 0; h < m_hinges.size(); ++h)
    m_rest_hinges[h] = make_rest_hinge(hinge_corners(x, static_cast<int>(h)), m_hinge_modulus[h]);
}

Vector12d BalloonModel::hinge_corners(const Eigen::VectorXd& x, int hinge) const {
  Vector12d c;
  for (int k = 0; k < 4; ++k) c.segment<3>(3 * k) = x.segment<3>(3 * m_hinges[static_cast<size_t>(hinge)][static_cast<size_t>(k)]);
  return c;
}

Vector9d BalloonModel::corners(const Eigen::VectorXd& x, int face) const {
  Vector9d c;
  for (int k = 0; k < 3; ++k) c.segment<3>(3 * k) = x.segment<3>(3 * m_faces(face, k));
  return c;
}

double BalloonModel::elastic_energy(const Eigen::VectorXd& x) const {
  double total = 0.0;
  for (int f = 0; f < m_faces.rows(); ++f) {
    total += membrane_energy(m_material, m_thickness[static_cast<size_t>(f)], m_rest_triangles[static_cast<size_t>(f)],
                             corners(x, f), m_tension_field);
    if (!std::isfinite(total)) return std::numeric_limits<double>::infinity();
  }
  for (size_t h = 0; h < m_hinges.size(); ++h)
    total += hinge_energy(m_rest_hinges[h], hinge_corners(x, static_cast<int>(h)));
  return std::isfinite(total) ? total : std::numeric_limits<double>::infinity();
}

Eigen::VectorXd BalloonModel::elastic_gradient(const Eigen::VectorXd& x) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  for (int f = 0; f < m_faces.rows(); ++f) {
    const Vector9d ge = membrane_gradient(m_material, m_thickness[static_cast<size_t>(f)],
                                          m_rest_triangles[static_cast<size_t>(f)], corners(x, f), m_tension_field);
    for (int k = 0; k < 3; ++k) g.segment<3>(3 * m_faces(f, k)) += ge.segment<3>(3 * k);
  }
  for (size_t h = 0; h < m_hinges.size(); ++h) {
    const Vector12d gradient = hinge_energy_gradient(m_rest_hinges[h], hinge_corners(x, static_cast<int>(h)));
    for (int k = 0; k < 4; ++k) g.segment<3>(3 * m_hinges[h][static_cast<size_t>(k)]) += gradient.segment<3>(3 * k);
  }
  return g;
}

double BalloonModel::volume(const Eigen::VectorXd& x) const {
  double v = 0.0;
  for (int f = 0; f < m_faces.rows(); ++f) v += triangle_signed_volume(corners(x, f));
  return v;
}

Eigen::VectorXd BalloonModel::volume_gradient(const Eigen::VectorXd& x) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  for (int f = 0; f < m_faces.rows(); ++f) {
    const Vector9d ge = triangle_volume_gradient(corners(x, f));
    for (int k = 0; k < 3; ++k) g.segment<3>(3 * m_faces(f, k)) += ge.segment<3>(3 * k);
  }
  return g;
}

double BalloonModel::area(const Eigen::VectorXd& x) const {
  double a = 0.0;
  for (int f = 0; f < m_faces.rows(); ++f) {
    const Vector9d c = corners(x, f);
    a += 0.5 * (c.segment<3>(3) - c.segment<3>(0)).cross(c.segment<3>(6) - c.segment<3>(0)).norm();
  }
  return a;
}

double BalloonModel::max_stretch(const Eigen::VectorXd& x) const {
  double largest = 0.0;
  for (int f = 0; f < m_faces.rows(); ++f)
    largest = std::max(largest, principal_stretches_squared(m_rest_triangles[static_cast<size_t>(f)], corners(x, f))[1]);
  return std::sqrt(largest);
}

int BalloonModel::relaxed_triangle_count(const Eigen::VectorXd& x) const {
  int count = 0;
  for (int f = 0; f < m_faces.rows(); ++f)
    if (is_relaxed(m_rest_triangles[static_cast<size_t>(f)], corners(x, f))) ++count;
  return count;
}

void BalloonModel::assemble_hessian(const Eigen::VectorXd& x, double pressure_mpa, TriangleAssembly& assembly,
                                    bool project_membrane) const {
  assembly.set_zero();
  double energy;
  Vector9d gradient;
  Matrix9d hessian;
  for (int f = 0; f < m_faces.rows(); ++f) {
    const Vector9d c = corners(x, f);
    membrane_energy_gradient_hessian(m_material, m_thickness[static_cast<size_t>(f)],
                                     m_rest_triangles[static_cast<size_t>(f)], c, energy, gradient, hessian,
                                     project_membrane, m_tension_field);
    if (pressure_mpa != 0.0) hessian -= pressure_mpa * triangle_volume_hessian(c);
    assembly.add(f, hessian);
  }
  double hinge_energy_value;
  Vector12d hinge_gradient;
  Matrix12d hinge_hessian;
  for (size_t h = 0; h < m_hinges.size(); ++h) {
    hinge_energy_gradient_hessian(m_rest_hinges[h], hinge_corners(x, static_cast<int>(h)), hinge_energy_value,
                                  hinge_gradient, hinge_hessian, project_membrane);
    assembly.add_hinge(static_cast<int>(h), hinge_hessian);
  }
}

}  // namespace balloon::fem
