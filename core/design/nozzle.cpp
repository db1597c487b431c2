#include "design/nozzle.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <queue>
#include <sstream>

#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

bool parse_double(const std::string& text, double& value) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  const char* first = t.data();
  const char* last = t.data() + t.size();
  if (*first == '+') ++first;  // from_chars does not take a leading '+'
  const auto [end, ec] = std::from_chars(first, last, value);
  return ec == std::errc() && end == last && std::isfinite(value);
}

std::string format_mm(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.4g mm", value);
  return buffer;
}

}  // namespace

Result<NozzleSpec> parse_nozzle(const std::string& text) {
  std::string lower = trim(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  NozzleSpec spec;
  if (lower == "auto") {
    spec.automatic = true;
    return spec;
  }
  std::vector<std::string> parts;
  std::stringstream stream(text);
  std::string part;
  while (std::getline(stream, part, ',')) parts.push_back(part);
  if (!text.empty() && text.back() == ',') parts.push_back("");
  if (parts.size() != 3 && parts.size() != 4) {
    return fail("nozzle must be 'auto' or 'X,Y,Z[,RADIUS]' in mm, got '" + text + "'");
  }
  double values[4] = {0.0, 0.0, 0.0, 0.0};
  for (size_t i = 0; i < parts.size(); ++i) {
    if (!parse_double(parts[i], values[i])) {
      return fail("nozzle: '" + trim(parts[i]) + "' is not a finite number (in '" + text + "')");
    }
  }
  spec.center = Eigen::Vector3d(values[0], values[1], values[2]);
  if (parts.size() == 4) {
    if (!(values[3] > 0.0)) return fail("nozzle radius must be > 0 mm, got " + trim(parts[3]));
    spec.radius_mm = values[3];
  }
  return spec;
}

Result<NozzleSelection> select_nozzle(const TriMesh& rest, const NozzleSpec& spec) {
  const int n = rest.vertex_count();
  if (n == 0 || rest.face_count() == 0) return fail("nozzle: the mesh is empty");
  const double diagonal = bounding_box_diagonal(rest.vertices);
  NozzleSelection out;
  out.radius_mm = spec.radius_mm > 0.0 ? spec.radius_mm : DEFAULT_NOZZLE_RADIUS_FRACTION * diagonal;

  int closest = 0;
  if (spec.automatic) {
    rest.vertices.col(2).minCoeff(&closest);  // first minimum: lowest index on ties
  } else {
    (rest.vertices.rowwise() - spec.center.transpose()).rowwise().squaredNorm().minCoeff(&closest);
    const double gap = (rest.vertices.row(closest).transpose() - spec.center).norm();
    if (gap > std::max(out.radius_mm, 0.1 * diagonal)) {
      return fail("nozzle centre (" + format_mm(spec.center.x()) + ", " + format_mm(spec.center.y()) + ", " +
                  format_mm(spec.center.z()) + ") is " + format_mm(gap) +
                  " from the nearest surface vertex: give a point on the balloon's surface");
    }
  }
  out.center_vertex = closest;
  out.center = rest.vertices.row(closest).transpose();

  // Vertex adjacency from the faces.
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(n));
  for (int f = 0; f < rest.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = rest.faces(f, k), b = rest.faces(f, (k + 1) % 3);
      neighbours[static_cast<size_t>(a)].push_back(b);
      neighbours[static_cast<size_t>(b)].push_back(a);
    }
  }
  std::vector<char> selected(static_cast<size_t>(n), 0);
  std::queue<int> queue;
  selected[static_cast<size_t>(closest)] = 1;
  queue.push(closest);
  const double r2 = out.radius_mm * out.radius_mm;
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop();
    for (const int w : neighbours[static_cast<size_t>(v)]) {
      if (selected[static_cast<size_t>(w)]) continue;
      const bool ring = v == closest;  // the one-ring is always held, however small the radius
      if (ring || (rest.vertices.row(w).transpose() - out.center).squaredNorm() <= r2) {
        selected[static_cast<size_t>(w)] = 1;
        queue.push(w);
      }
    }
  }
  for (int v = 0; v < n; ++v) {
    if (selected[static_cast<size_t>(v)]) out.vertices.push_back(v);
  }
  // Outward axis: area-weighted normals of the faces touching the selection.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  for (int f = 0; f < rest.face_count(); ++f) {
    const int a = rest.faces(f, 0), b = rest.faces(f, 1), c = rest.faces(f, 2);
    if (!selected[static_cast<size_t>(a)] && !selected[static_cast<size_t>(b)] && !selected[static_cast<size_t>(c)]) continue;
    const Eigen::Vector3d pa = rest.vertices.row(a), pb = rest.vertices.row(b), pc = rest.vertices.row(c);
    axis += (pb - pa).cross(pc - pa);
  }
  out.axis = axis.norm() > 0.0 ? Eigen::Vector3d(axis.normalized()) : Eigen::Vector3d(0, 0, -1);
  return out;
}

}  // namespace balloon
