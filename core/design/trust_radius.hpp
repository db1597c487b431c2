#pragma once
/// The trust region of the reduced design's steps: the largest distance (mm) a step may move any rest
/// vertex. It learns from two things: how far the line search had to cut the last step (a trial
/// equilibrium that failed beyond), and how well the last uncut step's decrease agreed with the
/// Gauss-Newton model's prediction.

namespace balloon {

/// The Gauss-Newton model's decrease for the step t d: -(t g.d + t^2 d.A.d / 2) = -t g.d (1 - t/2), since
/// a conjugate-gradient iterate from zero has d.A.d = -g.d. `slope` is g.d (negative for descent).
double gauss_newton_model_decrease(double t, double slope);

class TrustRadius {
 public:
  /// Starts at its largest, `max_radius_mm`.
  explicit TrustRadius(double max_radius_mm) : m_max(max_radius_mm), m_radius(max_radius_mm) {}

  double radius() const { return m_radius; }

  /// Back to its largest: what it learned no longer applies (the design moved to another branch).
  void start_over() { m_radius = m_max; }

  /// After an accepted step t of a direction whose largest vertex move is `largest_mm`, first tried at
  /// `first_t` (the radius' cut): cut k times, the radius shrinks by 2^k (t / first_t); uncut, a
  /// Gauss-Newton step whose decrease was under a quarter of its model's (`agreement`) halves the move
  /// it made (but shrinks the radius at most fourfold), one over three quarters doubles the radius (up
  /// to the largest), and between them it stays.
  /// Steps that are not Gauss-Newton steps (L-BFGS, steepest descent) have no model to agree with: uncut,
  /// they double it.
  void after_step(double first_t, double t, double largest_mm, double agreement, bool gauss_newton);

 private:
  double m_max;
  double m_radius;
};

}  // namespace balloon
