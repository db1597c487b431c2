/// `balloon mesh sphere`: write an icosphere, the analytic test balloon.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "arg_parser.hpp"
#include "cli_output.hpp"
#include "commands.hpp"
#include "exit_codes.hpp"
#include "jobs/json_writer.hpp"
#include "jobs/mesh_size.hpp"
#include "mesh/icosphere.hpp"

namespace balloon::cli {
namespace {

constexpr const char* COMMAND = "mesh";
constexpr int MAX_SUBDIVISIONS = 7;  // 163,842 vertices; make_icosphere's own limit

constexpr const char* HELP =
    "Usage: balloon mesh sphere --radius MM --subdivisions K --out FILE [--json]\n\n"
    "Writes an icosphere (subdivided icosahedron on a sphere, centred at the origin, faces outwards):\n"
    "10*4^K+2 vertices and 20*4^K faces (K=2: 162, K=3: 642, K=4: 2562, K=5: 10242 vertices).\n\n"
    "Options:\n"
    "  --radius MM          sphere radius in mm (> 0)\n"
    "  --subdivisions K     0..7\n"
    "  --out FILE           output mesh, format by extension: .obj, .stl or .ply\n"
    "  --json               print {\"out\", \"vertices\", \"faces\", \"radius_mm\"} as JSON\n"
    "  --help               this text\n\n"
    "Exit codes: 0 written, 2 bad input, 1 the file could not be written.\n";

const std::vector<OptionSpec> OPTIONS = {
    {"radius"}, {"subdivisions"}, {"out"},
};

}  // namespace

int run_mesh_command(const std::vector<std::string>& args, const GlobalOptions& global) {
  if (global.help) {
    std::fputs(HELP, stdout);
    return EXIT_OK;
  }
  Result<ParsedArgs> parsed = parse_args(args, OPTIONS);
  if (!parsed) return report_error(COMMAND, parsed.error(), EXIT_BAD_INPUT);
  if (parsed->positionals.empty()) return report_error(COMMAND, "missing what to make (try: balloon mesh sphere --help)", EXIT_BAD_INPUT);
  if (parsed->positionals.front() != "sphere")
    return report_error(COMMAND, "unknown mesh kind '" + parsed->positionals.front() + "' (known: sphere)", EXIT_BAD_INPUT);
  if (parsed->positionals.size() > 1)
    return report_error(COMMAND, "unexpected argument '" + parsed->positionals[1] + "'", EXIT_BAD_INPUT);

  const auto radius_text = parsed->get("radius");
  if (!radius_text) return report_error(COMMAND, "missing --radius MM", EXIT_BAD_INPUT);
  Result<double> radius = parse_number("radius", *radius_text);
  if (!radius) return report_error(COMMAND, radius.error(), EXIT_BAD_INPUT);
  // Its bounding-box diagonal (2 sqrt(3) radii) within any mesh's size limit: a larger one is refused at
  // every upload, so it is no use writing it (--radius 1e300 wrote coordinates of 1e299 mm).
  const double max_radius_mm = jobs::MAX_SIZE_MM / (2.0 * std::sqrt(3.0));
  if (!(*radius > 0.0 && *radius <= max_radius_mm)) {
    char limit[32];
    std::snprintf(limit, sizeof(limit), "%.6g", max_radius_mm);
    return report_error(COMMAND, "--radius must be positive and at most " + std::string(limit) + " mm, got " + *radius_text,
                        EXIT_BAD_INPUT);
  }

  const auto subdivisions_text = parsed->get("subdivisions");
  if (!subdivisions_text) return report_error(COMMAND, "missing --subdivisions K", EXIT_BAD_INPUT);
  Result<long long> subdivisions = parse_integer("subdivisions", *subdivisions_text, 0, MAX_SUBDIVISIONS);
  if (!subdivisions) return report_error(COMMAND, subdivisions.error(), EXIT_BAD_INPUT);

  const auto out_path = parsed->get("out");
  if (!out_path) return report_error(COMMAND, "missing --out FILE", EXIT_BAD_INPUT);
  if (const std::string problem = mesh_output_problem(*out_path); !problem.empty())
    return report_error(COMMAND, "--out: " + problem, EXIT_BAD_INPUT);

  const TriMesh sphere = make_icosphere(*radius, static_cast<int>(*subdivisions));
  Result<bool> written = write_mesh_file(sphere, *out_path);
  if (!written) return report_error(COMMAND, "--out: " + written.error(), EXIT_INTERNAL);

  if (global.json) {
    jobs::JsonWriter json;
    json.begin_object()
        .value("out", *out_path)
        .value("vertices", sphere.vertex_count())
        .value("faces", sphere.face_count())
        .value("radius_mm", *radius)
        .value("subdivisions", static_cast<int>(*subdivisions))
        .end_object();
    std::cout << json.str() << std::endl;
  } else {
    std::cout << "wrote " << *out_path << ": icosphere radius " << *radius << " mm, " << sphere.vertex_count()
              << " vertices, " << sphere.face_count() << " faces" << std::endl;
  }
  return EXIT_OK;
}

}  // namespace balloon::cli
