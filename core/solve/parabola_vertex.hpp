#pragma once
/// Where an extremum sampled at three points lies: the vertex of the parabola through them.

namespace balloon {

/// Vertex of the parabola through (x[i], y[i]), abscissae increasing; the vertex's abscissa is clamped to
/// [x[0], x[2]] and its ordinate is the parabola's value there.
void parabola_vertex(const double x[3], const double y[3], double* vertex_x, double* vertex_y);

}  // namespace balloon
