#include "design/design_objective.hpp"

#include <algorithm>
#include <cmath>

#include "mesh/mesh_geometry.hpp"

namespace balloon {

namespace {

/// A start hinge flatter than this (rad) counts as coplanar: it switches the rest-bending term on.
constexpr double COPLANAR_HINGE_RAD = 1e-3;
/// Rest-bending stiffness relative to E_dist's k_bending: enough to fix the null space of flat regions,
/// small enough not to pull the design away from the target.
constexpr double REST_BENDING_WEIGHT = 1e-2;
/// The rest mesh's barriers (rest_triangle_quality, rest_hinge_fold): a surface whose every triangle or
/// hinge is one unit past its threshold costs this times E_dist's total reference edge length (mm), about
/// 4 times E_dist at a typical start. One sliver 100 times flatter than its start triangle then costs
/// about E_dist at the start; changes up to the thresholds cost nothing.
constexpr double REST_QUALITY_WEIGHT = 1.0;
/// A stalled design whose inflated shape is further than this (relative to the diagonal, on average)
/// from its rigid placement on the target is re-placed and continues.
constexpr double REALIGN_TOLERANCE_REL = 1e-4;

double mean_edge_length(const TriMesh& mesh) {
  double total = 0.0;
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      total += (mesh.vertices.row(mesh.faces(f, k)) - mesh.vertices.row(mesh.faces(f, (k + 1) % 3))).norm();
  return total / (3.0 * std::max(1, mesh.face_count()));
}

}  // namespace

DesignObjective::DesignObjective(const TriMesh& target, const TriMesh& start, const DesignOptions& options,
                                 const fem::BalloonModel& model)
    : m_target(target),
      m_model(model),
      m_distance(target.vertices, target.faces, options.k_length, options.k_bending),
      m_surface(target),
      m_start_hinges(start.vertices, target.faces, 0.0, REST_BENDING_WEIGHT * options.k_bending),
      m_rest_quality(start.vertices, target.faces, REST_QUALITY_WEIGHT * m_distance.rest_lengths().sum()),
      m_rest_fold(m_start_hinges, REST_QUALITY_WEIGHT * m_distance.rest_lengths().sum()),
      m_start_volume(enclosed_volume(start.vertices, target.faces)) {
  // Rest-shape collisions: vertices closer than half a mean edge (eq. 24), costing one kd-tree pass
  // per accepted iteration and nothing else while no pair is near.
  SelfCollisionOptions collision;
  collision.stiffness = 10.0 / std::pow(mean_edge_length(start), 2);
  collision.contact_distance_mm = 0.5 * mean_edge_length(start);
  m_collision = std::make_unique<SelfCollision>(start, collision);
  // Coplanar rest triangles leave the membrane forces blind to normal motion of their shared
  // vertices (a null space of the rest-shape Hessian); only then does the rest-bending term (the
  // bending part of eq. 18 against the start) take part.
  m_rest_bending_active = (m_start_hinges.rest_angles().array().abs() < COPLANAR_HINGE_RAD).any();
  const double diag = m_surface.bbox_diagonal_mm();
  m_unit_surface_weight = m_distance.rest_lengths().sum() / (diag * diag * target.vertex_count());
  m_k_surface = options.k_surface;
  m_surface_growth = options.surface_growth;
  m_max_surface_growth = options.max_surface_growth;
  m_surface_growth_iterations = options.surface_growth_iterations;
}

bool DesignObjective::grow_surface_weight(int iterations) {
  const double growth = std::min(m_max_surface_growth,
                                 std::pow(m_surface_growth, std::max(0, iterations) / m_surface_growth_iterations));
  if (growth == m_surface_growth_now) return false;
  m_surface_growth_now = growth;
  return surface_weight_mm() > 0.0;
}

double DesignObjective::value(const Eigen::VectorXd& rest, const Eigen::VectorXd& x) const {
  return m_distance.value(x) + surface_term(x, nullptr) + regularizer_value(rest);
}

Eigen::VectorXd DesignObjective::shape_gradient(const Eigen::VectorXd& x) const {
  Eigen::VectorXd gradient;
  m_distance.gradient(x, gradient);
  Eigen::VectorXd surface_gradient;
  surface_term(x, &surface_gradient);
  gradient += surface_gradient;
  return gradient;
}

/// E_surf = k_s L mean_i (d_i / diag)^2: the squared point-to-surface distances of the inflated
/// vertices at their Procrustes placement on the target (the error the result reports, in the same
/// placement), scaled like E_dist per mm of reference edge (L = total reference edge length, mm). So it
/// is rigid-invariant, as E_dist is. Its gradient is J_P^T 2 w (P_i - c_i) with c_i the closest target
/// point (the derivative of a squared distance to a surface, wherever the closest point is unique).
double DesignObjective::surface_term(const Eigen::VectorXd& x, Eigen::VectorXd* gradient) const {
  if (surface_weight_mm() <= 0.0) {
    if (gradient) gradient->setZero(x.size());
    return 0.0;
  }
  const ProcrustesPlacement placement(unflatten(x), m_target.vertices);
  const Positions& points = placement.placed();
  Positions closest;
  Eigen::VectorXd distances;
  m_surface.closest_points(points, closest, &distances);
  if (gradient) *gradient = placement.pull_back(2.0 * surface_weight_mm() * flat(Positions(points - closest)));
  return surface_weight_mm() * distances.squaredNorm();
}

double DesignObjective::regularizer_value(const Eigen::VectorXd& rest) const {
  double value = 0.0;
  if (m_collision->any_active()) value += m_collision->value(rest);
  if (m_rest_bending_active) value += m_start_hinges.value(rest);
  if (m_max_volume_weight > 0.0) value -= m_max_volume_weight * enclosed_volume(unflatten(rest), m_target.faces);
  value += m_rest_quality.value(rest) + m_rest_fold.value(rest);
  return value;
}

void DesignObjective::add_regularizer_gradient(const Eigen::VectorXd& rest, Eigen::Ref<Eigen::VectorXd> gradient) const {
  Eigen::VectorXd part;
  if (m_collision->any_active()) {
    m_collision->gradient(rest, part);
    gradient += part;
  }
  if (m_rest_bending_active) {
    m_start_hinges.gradient(rest, part);
    gradient += part;
  }
  if (m_max_volume_weight > 0.0) gradient -= m_max_volume_weight * m_model.volume_gradient(rest);
  m_rest_quality.add_gradient(rest, gradient);
  m_rest_fold.add_gradient(rest, gradient);
}

Eigen::VectorXd DesignObjective::regularizer_gauss_newton_times(const Eigen::VectorXd& rest,
                                                                const Eigen::VectorXd& direction) const {
  return m_rest_quality.gauss_newton_times(rest, direction) + m_rest_fold.gauss_newton_times(rest, direction);
}

void DesignObjective::note_rest_barriers(const Eigen::VectorXd& rest, DesignResult& result) {
  if (!m_rest_quality_seen && m_rest_quality.distorted_count(rest) > 0) {
    m_rest_quality_seen = true;
    result.active_terms.push_back("rest_quality");
  }
  if (!m_rest_fold_seen && m_rest_fold.folded_count(rest) > 0) {
    m_rest_fold_seen = true;
    result.active_terms.push_back("rest_fold");
  }
}

Positions DesignObjective::closest_target_normals(const Positions& points) const {
  Positions closest;
  Eigen::VectorXi faces;
  m_surface.closest_points(points, closest, nullptr, &faces);
  Positions normals = Positions::Zero(points.rows(), 3);
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    const Eigen::Vector3d a = m_target.vertices.row(m_target.faces(faces[v], 0));
    const Eigen::Vector3d b = m_target.vertices.row(m_target.faces(faces[v], 1));
    const Eigen::Vector3d c = m_target.vertices.row(m_target.faces(faces[v], 2));
    const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
    if (normal.allFinite()) normals.row(v) = normal.transpose();
  }
  return normals;
}

ObjectiveGaussNewton DesignObjective::gauss_newton(const Eigen::VectorXd& x) const {
  std::vector<Eigen::Triplet<double>> entries;
  m_distance.residual_jacobian_triplets(x, entries);
  Eigen::SparseMatrix<double, Eigen::RowMajor> jacobian(m_distance.residual_count(), x.size());
  jacobian.setFromTriplets(entries.begin(), entries.end());
  if (surface_weight_mm() <= 0.0) return ObjectiveGaussNewton(std::move(jacobian), Positions::Zero(0, 3), 0.0, nullptr);
  auto placement = std::make_shared<const ProcrustesPlacement>(unflatten(x), m_target.vertices);
  Positions normals = closest_target_normals(placement->placed());
  return ObjectiveGaussNewton(std::move(jacobian), std::move(normals), surface_weight_mm(), std::move(placement));
}

/// Point-to-plane: 2 w n n^T per vertex with n the normal of the target triangle closest to it (sliding
/// along the target costs nothing; E_dist governs that), turned back into x's frame. Sparse, so without
/// the placement's rank-6 coupling that gauss_newton() keeps.
void DesignObjective::add_surface_hessian(const Eigen::VectorXd& x, std::vector<Eigen::Triplet<double>>& triplets,
                                          int dof_offset) const {
  if (surface_weight_mm() <= 0.0) return;
  const ProcrustesPlacement placement(unflatten(x), m_target.vertices);
  const Positions normals = closest_target_normals(placement.placed()) * placement.transform().rotation;
  for (Eigen::Index v = 0; v < normals.rows(); ++v) {
    const Eigen::Vector3d normal = normals.row(v).transpose();
    if (normal.isZero()) continue;
    const Eigen::Matrix3d block = 2.0 * surface_weight_mm() * normal * normal.transpose();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        triplets.emplace_back(dof_offset + 3 * static_cast<int>(v) + i, dof_offset + 3 * static_cast<int>(v) + j,
                              block(i, j));
  }
}

bool DesignObjective::update_collisions(const Eigen::VectorXd& rest, DesignResult& result) {
  const bool was_colliding = m_collision->any_active();
  const bool colliding = m_collision->update(rest) > 0;
  if (colliding && !m_collision_seen) {
    m_collision_seen = true;
    result.active_terms.push_back("collision");
  }
  return colliding || was_colliding;
}

void DesignObjective::update_max_volume_term(const Eigen::VectorXd& rest, double start_distance, DesignResult& result) {
  if (m_max_volume_weight > 0.0 || inverted_hinges(rest) == 0) return;
  m_max_volume_weight = start_distance / m_start_volume;
  result.active_terms.push_back("max_volume");
}

/// A hinge whose angle moved more than a right angle from the start's: a region turned inside out
/// (mirrored through its planar rim), which inflates to nearly the same shape.
int DesignObjective::inverted_hinges(const Eigen::VectorXd& rest) const {
  const auto& edges = m_start_hinges.edges();
  const Eigen::VectorXd& start_angles = m_start_hinges.rest_angles();
  int count = 0;
  for (int h = 0; h < m_start_hinges.hinge_count(); ++h) {
    const double angle = dihedral_angle(rest.segment<3>(3 * edges(h, 0)), rest.segment<3>(3 * edges(h, 1)),
                                        rest.segment<3>(3 * edges(h, 2)), rest.segment<3>(3 * edges(h, 3)));
    if (std::abs(angle - start_angles[h]) > 0.5 * M_PI) ++count;
  }
  return count;
}

bool DesignObjective::realign(Eigen::VectorXd& x) const {
  if (surface_weight_mm() <= 0.0) return false;
  const Positions current = unflatten(x);
  const Positions aligned = rigid_align_to(current, m_target.vertices);
  if ((aligned - current).rowwise().norm().mean() <= REALIGN_TOLERANCE_REL * m_surface.bbox_diagonal_mm()) return false;
  x = flat(aligned);
  return true;
}

void DesignObjective::list_common_terms(DesignResult& result, bool nozzle) const {
  result.active_terms.push_back("distance");
  if (surface_weight_mm() > 0.0) result.active_terms.push_back("surface");
  if (nozzle) result.active_terms.push_back("nozzle");
  if (m_rest_bending_active) result.active_terms.push_back("rest_bending");
}

}  // namespace balloon
