#include "simulate_request.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "field_flags.hpp"
#include "jobs/simulate_job.hpp"
#include "material/material.hpp"
#include "material_argument.hpp"

namespace balloon::cli {

std::vector<OptionSpec> simulate_option_specs() {
  return {{"material"}, {"thickness"}, {"size"}, {"pressure"}, {"volume-ratio"}, {"volume-ratio-range"}, {"pressure-range"}, {"points"}};
}

namespace {

/// "A:B" as two finite numbers, or an error naming the option.
Result<std::pair<double, double>> parse_range(const std::string& option, const std::string& text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    return fail("--" + option + ": '" + text + "' is not a range A:B");
  Result<double> from = parse_number(option, text.substr(0, colon));
  if (!from) return fail(from.error());
  Result<double> to = parse_number(option, text.substr(colon + 1));
  if (!to) return fail(to.error());
  return std::make_pair(*from, *to);
}

}  // namespace

balloon::v1::MeshFormat mesh_format_from_path(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".obj") return balloon::v1::MESH_FORMAT_OBJ;
  if (extension == ".stl") return balloon::v1::MESH_FORMAT_STL;
  if (extension == ".ply") return balloon::v1::MESH_FORMAT_PLY;
  if (extension == ".off") return balloon::v1::MESH_FORMAT_OFF;
  if (extension == ".gltf") return balloon::v1::MESH_FORMAT_GLTF;
  if (extension == ".glb") return balloon::v1::MESH_FORMAT_GLB;
  return balloon::v1::MESH_FORMAT_UNSPECIFIED;
}

Result<balloon::v1::SubmitJobRequest> simulate_request_from_args(const ParsedArgs& args) {
  if (args.positionals.empty()) return fail("missing REST_MESH (see --help)");
  if (args.positionals.size() > 1)
    return fail("expected one REST_MESH, got " + std::to_string(args.positionals.size()) + " paths");
  const std::string& mesh_path = args.positionals.front();

  balloon::v1::SubmitJobRequest request;
  balloon::v1::SimulateJob* job = request.mutable_spec()->mutable_simulate();

  const std::optional<std::string> spec = args.get("material");
  if (!spec) return fail("missing --material SPEC");
  Result<balloon::v1::MaterialRef> material = material_reference(*spec);
  if (!material) return fail(material.error());
  *job->mutable_material() = std::move(*material);

  jobs::SimulateParameters parameters;
  if (const auto text = args.get("thickness")) {
    Result<double> value = parse_number("thickness", *text);
    if (!value) return fail(value.error());
    parameters.thickness_mm = *value;
  }
  if (const auto text = args.get("size")) {
    Result<double> value = parse_number("size", *text);
    if (!value) return fail(value.error());
    parameters.size_mm = *value;
  }
  if (const auto text = args.get("pressure")) {
    Result<double> value = parse_number("pressure", *text);
    if (!value) return fail(value.error());
    parameters.pressure_kpa = *value;
  }
  if (const auto text = args.get("volume-ratio")) {
    Result<double> value = parse_number("volume-ratio", *text);
    if (!value) return fail(value.error());
    parameters.volume_ratio = *value;
  }
  const std::optional<std::string> volume_range = args.get("volume-ratio-range");
  const std::optional<std::string> pressure_range = args.get("pressure-range");
  if (volume_range && pressure_range) return fail("give --volume-ratio-range or --pressure-range, not both");
  if (volume_range || pressure_range) {
    const char* option = volume_range ? "volume-ratio-range" : "pressure-range";
    Result<std::pair<double, double>> range = parse_range(option, volume_range ? *volume_range : *pressure_range);
    if (!range) return fail(range.error());
    const std::optional<std::string> points_text = args.get("points");
    if (!points_text) return fail("--points N is needed with --" + std::string(option));
    // Bounded by the job's own check (its message names the limits); this only keeps the int in range.
    Result<long long> points = parse_integer("points", *points_text, -1000000, 1000000);
    if (!points) return fail(points.error());
    jobs::CurveParameters curve;
    curve.control = volume_range ? InflationControl::VolumeRatio : InflationControl::Pressure;
    curve.from = range->first;
    curve.to = range->second;
    curve.points = static_cast<int>(*points);
    parameters.curve = curve;
  } else if (args.has("points")) {
    return fail("--points needs --volume-ratio-range or --pressure-range");
  }
  if (const std::vector<jobs::FieldProblem> problems = jobs::simulate_parameter_problems(parameters); !problems.empty())
    return fail(message_naming_flags("simulate", problems));
  job->set_thickness_mm(parameters.thickness_mm);
  job->set_size_mm(parameters.size_mm);
  if (parameters.pressure_kpa) job->set_pressure_kpa(*parameters.pressure_kpa);
  if (parameters.volume_ratio) job->set_volume_ratio(*parameters.volume_ratio);
  if (const auto& curve = parameters.curve) {
    balloon::v1::ValueRange* range = curve->control == InflationControl::VolumeRatio
                                         ? job->mutable_curve()->mutable_volume_ratio_range()
                                         : job->mutable_curve()->mutable_pressure_range();
    range->set_from(curve->from);
    range->set_to(curve->to);
    job->mutable_curve()->set_points(curve->points);
  }

  const balloon::v1::MeshFormat format = mesh_format_from_path(mesh_path);
  std::error_code error;
  if (!std::filesystem::exists(mesh_path, error)) return fail("cannot read mesh '" + mesh_path + "': no such file");
  if (format == balloon::v1::MESH_FORMAT_UNSPECIFIED)
    return fail("cannot read mesh '" + mesh_path + "': unknown extension (obj, stl, ply, off, gltf, glb)");
  std::ifstream in(mesh_path, std::ios::binary);
  if (!in) return fail("cannot read mesh '" + mesh_path + "'");
  // Straight into the request (a 100k-vertex OBJ is 7.5 MB: no intermediate copies).
  std::string* data = job->mutable_rest_mesh()->mutable_data();
  const std::uintmax_t size = std::filesystem::file_size(mesh_path, error);
  if (error) return fail("cannot read mesh '" + mesh_path + "'");
  data->resize(static_cast<std::size_t>(size));
  if (!in.read(data->data(), static_cast<std::streamsize>(size)) || in.peek() != std::char_traits<char>::eof())
    return fail("cannot read mesh '" + mesh_path + "' (it changed while being read)");
  job->mutable_rest_mesh()->set_format(format);
  return request;
}

}  // namespace balloon::cli
