#include "design/thickness_tolerance.hpp"

#include <algorithm>
#include <random>
#include <stdexcept>

#include "design/surface_distance.hpp"
#include "mesh/mesh_geometry.hpp"

namespace balloon {
namespace {

constexpr double PERTURBATION_LEVELS[] = {0.10, 0.20};

}  // namespace

ThicknessTolerance thickness_tolerance(const TriMesh& rest, const InflationOptions& nominal_options,
                                       const Positions& nominal_inflated, int samples, unsigned seed) {
  if (nominal_inflated.rows() != rest.vertex_count() || nominal_inflated.cols() != 3)
    throw std::invalid_argument("thickness_tolerance: nominal_inflated must be #V by 3");
  const int face_count = rest.face_count();
  const bool per_element = !nominal_options.element_thickness_mm.empty();
  if (per_element && static_cast<int>(nominal_options.element_thickness_mm.size()) != face_count)
    throw std::invalid_argument("thickness_tolerance: element_thickness_mm must have #F entries");

  InflationOptions options = nominal_options;
  options.control = InflationControl::VolumeRatio;
  options.volume_ratio = enclosed_volume(nominal_inflated, rest.faces) / enclosed_volume(rest.vertices, rest.faces);
  options.progress = nullptr;  // per-sample solver chatter is not the caller's progress

  ThicknessTolerance tolerance;
  // One generator for the whole run, levels in a fixed order: the same seed gives the same thicknesses.
  std::mt19937 generator(seed);
  for (const double level : PERTURBATION_LEVELS) {
    ThicknessToleranceLevel result;
    result.perturbation = level;
    double deviation_sum = 0.0;
    for (int sample = 0; sample < samples; ++sample) {
      if (nominal_options.cancel != nullptr && nominal_options.cancel->cancelled()) break;
      // std::uniform_real_distribution is implementation-defined; mapping the raw 32-bit draws ourselves
      // keeps the numbers the same across standard libraries.
      options.element_thickness_mm.assign(static_cast<std::size_t>(face_count), 0.0);
      for (int face = 0; face < face_count; ++face) {
        const double unit = static_cast<double>(generator()) / 4294967295.0;  // [0, 1]
        const double nominal = per_element ? nominal_options.element_thickness_mm[static_cast<std::size_t>(face)]
                                           : nominal_options.thickness_mm;
        options.element_thickness_mm[static_cast<std::size_t>(face)] = nominal * (1.0 + level * (2.0 * unit - 1.0));
      }
      const InflationResult inflated = inflate(rest, options, &nominal_inflated);
      if (!inflated.converged) {
        ++result.failed_samples;
        continue;
      }
      const Positions aligned = rigid_align_to(inflated.deformed, nominal_inflated);
      const Eigen::VectorXd distances = (aligned - nominal_inflated).rowwise().norm();
      deviation_sum += distances.mean();
      result.max_deviation_mm = std::max(result.max_deviation_mm, distances.maxCoeff());
      ++result.samples;
    }
    result.mean_deviation_mm = result.samples > 0 ? deviation_sum / result.samples : 0.0;
    tolerance.levels.push_back(result);
  }
  return tolerance;
}

}  // namespace balloon
