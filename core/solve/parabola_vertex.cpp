#include "solve/parabola_vertex.hpp"

#include <algorithm>

namespace balloon {

void parabola_vertex(const double x[3], const double y[3], double* vertex_x, double* vertex_y) {
  const double a = (x[1] - x[0]) * (y[1] - y[2]), b = (x[1] - x[2]) * (y[1] - y[0]);
  const double denominator = a - b;
  double xv = x[1];
  if (denominator != 0.0) xv = x[1] - 0.5 * ((x[1] - x[0]) * a - (x[1] - x[2]) * b) / denominator;
  xv = std::clamp(xv, x[0], x[2]);
  // Lagrange form of the same parabola at xv.
  double yv = 0.0;
  for (int i = 0; i < 3; ++i) {
    double weight = 1.0;
    for (int j = 0; j < 3; ++j)
      if (j != i) weight *= (xv - x[j]) / (x[i] - x[j]);
    yv += weight * y[i];
  }
  *vertex_x = xv;
  *vertex_y = yv;
}

}  // namespace balloon
