#include "mesh/centred_frame.hpp"

namespace balloon {

CentredFrame::CentredFrame(const Positions& vertices) {
  if (vertices.rows() > 0 && vertices.allFinite())
    m_centre = 0.5 * (vertices.colwise().minCoeff() + vertices.colwise().maxCoeff());
}

Positions CentredFrame::centred(const Positions& caller) const {
  if (caller.rows() == 0) return caller;
  return caller.rowwise() - m_centre;
}

Positions CentredFrame::caller(const Positions& centred) const {
  if (centred.rows() == 0) return centred;
  return centred.rowwise() + m_centre;
}

}  // namespace balloon
