#include "design/trust_radius.hpp"

#include <algorithm>

namespace balloon {

double gauss_newton_model_decrease(double t, double slope) { return -t * slope * (1.0 - 0.5 * t); }

void TrustRadius::after_step(double first_t, double t, double largest_mm, double agreement, bool gauss_newton) {
  // Not set to the step taken when cut: a short direction's step (a barrier's, 1e-6 mm) that needed one
  // halving had set it there, and the next full-size direction started at t = 2e-6 and spent the rest of
  // the budget doubling it back (latex teddy, stalled).
  if (t < first_t)
    m_radius *= t / first_t;
  // Nor, after a disagreeing step far shorter than the radius, to half that step: the latex cactus near a
  // fold took a Gauss-Newton direction of 7e-5 mm inside a 0.05 mm radius, then spent ten iterations
  // doubling the radius back from 4e-5 mm and stalled at the baseline.
  else if (gauss_newton && agreement < 0.25)
    m_radius = std::max(0.5 * t * largest_mm, 0.25 * m_radius);
  else if (!gauss_newton || agreement > 0.75)
    m_radius = std::min(m_max, 2.0 * m_radius);
}

}  // namespace balloon
