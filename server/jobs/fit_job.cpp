#include "jobs/fit_job.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cctype>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "jobs/json_writer.hpp"
#include "calibration/axisymmetric_bulge.hpp"

namespace balloon::jobs {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string number(double value) { return json_number(value); }

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string regimes_text(bool inflection, bool stiffening) {
  if (inflection && stiffening) return "inflection and stiffening";
  if (inflection) return "inflection";
  if (stiffening) return "stiffening";
  return "neither";
}

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  static constexpr std::array<uint32_t, 64> K = {
      0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98,
      0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
      0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8,
      0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
      0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819,
      0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
      0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
      0xc67178f2};
  std::array<uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                               0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::string message(bytes);
  const uint64_t bit_length = static_cast<uint64_t>(bytes.size()) * 8;
  message.push_back(static_cast<char>(0x80));
  while (message.size() % 64 != 56) message.push_back('\0');
  for (int i = 7; i >= 0; --i) message.push_back(static_cast<char>((bit_length >> (8 * i)) & 0xff));
  auto rotr = [](uint32_t x, int n) { return (x >> n) | (x << (32 - n)); };
  for (size_t chunk = 0; chunk < message.size(); chunk += 64) {
    std::array<uint32_t, 64> w{};
    for (int i = 0; i < 16; ++i)
      for (int b = 0; b < 4; ++b)
        w[static_cast<size_t>(i)] =
            (w[static_cast<size_t>(i)] << 8) | static_cast<uint8_t>(message[chunk + static_cast<size_t>(4 * i + b)]);
    for (size_t i = 16; i < 64; ++i) {
      const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::array<uint32_t, 8> v = h;
    for (size_t i = 0; i < 64; ++i) {
      const uint32_t S1 = rotr(v[4], 6) ^ rotr(v[4], 11) ^ rotr(v[4], 25);
      const uint32_t ch = (v[4] & v[5]) ^ (~v[4] & v[6]);
      const uint32_t t1 = v[7] + S1 + ch + K[i] + w[i];
      const uint32_t S0 = rotr(v[0], 2) ^ rotr(v[0], 13) ^ rotr(v[0], 22);
      const uint32_t maj = (v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]);
      const uint32_t t2 = S0 + maj;
      v = {t1 + t2, v[0], v[1], v[2], v[3] + t1, v[4], v[5], v[6]};
    }
    for (size_t i = 0; i < 8; ++i) h[i] += v[i];
  }
  static constexpr char HEX[] = "0123456789abcdef";
  std::string out;
  for (uint32_t word : h)
    for (int shift = 28; shift >= 0; shift -= 4) out.push_back(HEX[(word >> shift) & 0xf]);
  return out;
}

Result<FitInput> prepare_fit(const std::vector<FitDataFile>& files, const std::string& model) {
  FitInput input;
  if (model == "all") {
    input.all_models = true;
    input.models = {MaterialModel::HartSmith, MaterialModel::MooneyRivlin, MaterialModel::NeoHookean};
  } else {
    Result<MaterialModel> parsed = parse_model_name(model);
    if (!parsed) return fail(parsed.error() + " (or all)");
    input.models = {*parsed};
  }
  if (files.empty()) return fail("no measurement file given");
  std::string all_bytes;
  for (const FitDataFile& file : files) {
    Result<TestKind> kind = parse_test_kind(file.test);
    if (!kind) return fail(file.label + ": " + kind.error());
    Result<MeasurementSet> set = parse_measurements(file.csv_text, *kind, file.label);
    if (!set) return fail(file.label + ": " + set.error());
    if (*kind == TestKind::Bulge) {
      if (!(file.radius_mm > 0) || !std::isfinite(file.radius_mm))
        return fail(file.label + ": the bulge test needs the disc radius (--radius MM, > 0)");
      if (!(file.thickness_mm > 0) || !std::isfinite(file.thickness_mm))
        return fail(file.label + ": the bulge test needs the disc thickness (--thickness MM, > 0)");
      set->disc_radius_mm = file.radius_mm;
      set->thickness_mm = file.thickness_mm;
    }
    if (auto problem = measurement_problem(*set); !problem.empty()) return fail(file.label + ": " + problem);
    input.sets.push_back(std::move(*set));
    all_bytes += file.csv_text;
  }
  input.data_sha256 = sha256_hex(all_bytes);
  return input;
}

Result<FitOutcome> run_fit(const FitInput& input, const CancelToken* cancel) {
  FitOutcome outcome;
  const double start = now_s();
  FitOptions options;
  options.cancel = cancel;
  // Bulge sets: the exact axisymmetric membrane inside the least squares (one 1D solve per evaluation).
  options.bulge_model = axisymmetric_bulge_model();
  for (MaterialModel model : input.models) {
    if (cancel != nullptr && cancel->cancelled()) return fail(FIT_CANCELLED);
    Result<FitResult> fit = fit_material(model, input.sets, options);
    const bool cancelled = cancel != nullptr && cancel->cancelled();
    if (!fit && (cancelled || !input.all_models)) return fail(model_name(model) + ": " + fit.error());
    if (!fit) {
      outcome.skipped.push_back({model, fit.error()});
      continue;
    }
    outcome.fits.push_back(std::move(*fit));
  }
  if (outcome.fits.empty()) {
    std::string reasons;
    for (const FitSkip& skip : outcome.skipped) reasons += (reasons.empty() ? "" : "; ") + model_name(skip.model) + ": " + skip.reason;
    return fail("no law fits this data (" + reasons + ")");
  }
  outcome.time_s = now_s() - start;
  return outcome;
}

int best_fit_index(const FitOutcome& outcome) {
  int best = 0;
  for (size_t i = 1; i < outcome.fits.size(); ++i)
    if (outcome.fits[i].rms_relative_residual < outcome.fits[static_cast<size_t>(best)].rms_relative_residual)
      best = static_cast<int>(i);
  return best;
}

namespace {

/// The members of one fit's JSON object (see fit_json), into an open object.
void write_fit_members(JsonWriter& json, const FitResult& fit) {
  json.value("model", model_name(fit.material.model));
  json.value("spec", material_spec(fit.material));
  const std::vector<std::string> names = parameter_names(fit.material.model);
  json.begin_object("params");
  for (size_t i = 0; i < names.size(); ++i) json.value(names[i], fit.material.params[i]);
  json.end_object();
  json.begin_object("std_errors");
  for (size_t i = 0; i < names.size() && i < fit.std_errors.size(); ++i) json.value(names[i], fit.std_errors[i]);
  json.end_object();
  json.value("rms_residual", fit.rms_residual);
  json.value("max_residual", fit.max_residual);
  json.value("residual_unit", fit.residual_unit);
  json.value("rms_relative_residual", fit.rms_relative_residual);
  json.value("max_relative_residual", fit.max_relative_residual);
  json.value("points", fit.points);
  json.value("converged", fit.converged);
  json.begin_object("regimes");
  json.value("data_inflection", fit.data_inflection);
  json.value("data_stiffening", fit.data_stiffening);
  json.value("model_inflection", fit.model_inflection);
  json.value("model_stiffening", fit.model_stiffening);
  json.end_object();
  json.begin_array("sets");
  for (const SetFit& set : fit.sets) {
    json.begin_object();
    json.value("label", set.label);
    json.value("test", test_kind_name(set.kind));
    json.value("points", set.points);
    json.value("dropped_compression_points", set.dropped_compression_points);
    json.value("rms_residual", set.rms_residual);
    json.value("max_residual", set.max_residual);
    json.value("residual_unit", set.residual_unit);
    json.end_object();
  }
  json.end_array();
  json.value("message", fit.message);
}

}  // namespace

std::string fit_json(const FitResult& fit) {
  JsonWriter json;
  json.begin_object();
  write_fit_members(json, fit);
  json.end_object();
  return json.str();
}

std::string fit_report_json(const FitInput& input, const FitOutcome& outcome) {
  // The plot travels in the report so that a client without the data (the web page) can show it; it is
  // the whole plot (every model), so in the list form only the first object carries it.
  const std::string plot = fit_plot_svg(input, outcome);
  const bool list = input.all_models || outcome.fits.size() != 1;
  JsonWriter json;
  if (list) json.begin_array();
  for (size_t i = 0; i < outcome.fits.size(); ++i) {
    json.begin_object();
    write_fit_members(json, outcome.fits[i]);
    if (i == 0) json.value("plot_svg", plot);
    json.end_object();
  }
  for (const FitSkip& skip : outcome.skipped) {  // "all" only, so in the list
    json.begin_object();
    json.value("model", model_name(skip.model));
    json.value("skipped", skip.reason);
    json.end_object();
  }
  if (list) json.end_array();
  return json.str();
}

std::string fit_summary_text(const FitInput& input, const FitOutcome& outcome) {
  std::ostringstream out;
  out.precision(4);
  out << "fitted " << outcome.fits.size() << " model(s) to " << input.sets.size() << " data set(s) in "
      << outcome.time_s << " s\n";
  for (const FitResult& fit : outcome.fits) {
    out << "\n" << model_name(fit.material.model) << ": " << material_spec(fit.material) << "\n";
    const std::vector<std::string> names = parameter_names(fit.material.model);
    for (size_t i = 0; i < names.size(); ++i) {
      out << "  " << names[i] << " = " << fit.material.params[i];
      if (i < fit.std_errors.size()) out << " +- " << fit.std_errors[i];
      out << (names[i] == "k1" || names[i] == "k2" ? "" : " MPa") << "\n";
    }
    out << "  residuals over " << fit.points << " points: rms " << fit.rms_residual << " " << fit.residual_unit
        << ", max " << fit.max_residual << " " << fit.residual_unit << " (relative rms "
        << 100 * fit.rms_relative_residual << "%)\n";
    for (const SetFit& set : fit.sets)
      out << "  " << set.label << " (" << test_kind_name(set.kind) << ", " << set.points << " points"
          << (set.dropped_compression_points > 0
                  ? "; " + std::to_string(set.dropped_compression_points) +
                        (set.dropped_compression_points == 1 ? " row" : " rows") +
                        " with stretch below 1 left out: compression is not fitted"
                  : std::string())
          << "): rms " << set.rms_residual << " " << set.residual_unit << ", max " << set.max_residual << " " << set.residual_unit
          << "\n";
    out << "  regimes: data " << regimes_text(fit.data_inflection, fit.data_stiffening) << ", model "
        << regimes_text(fit.model_inflection, fit.model_stiffening) << "\n";
    if (!fit.converged) out << "  note: " << fit.message << "\n";
  }
  for (const FitSkip& skip : outcome.skipped)
    out << "\n" << model_name(skip.model) << ": not fitted: " << skip.reason << "\n";
  if (outcome.fits.size() > 1) {
    const FitResult& best = outcome.fits[static_cast<size_t>(best_fit_index(outcome))];
    out << "\nbest: " << model_name(best.material.model) << "\n";
  }
  return out.str();
}

std::string fit_plot_svg(const FitInput& input, const FitOutcome& outcome) {
  constexpr double WIDTH = 640, PANEL = 400, LEFT = 70, RIGHT = 150, TOP = 30, BOTTOM = 50;
  static constexpr const char* COLORS[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd"};
  const double height = PANEL * static_cast<double>(input.sets.size());
  std::ostringstream svg;
  svg.precision(6);
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << WIDTH << "\" height=\"" << height
      << "\" viewBox=\"0 0 " << WIDTH << " " << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  FitOptions options;
  options.bulge_model = axisymmetric_bulge_model();
  for (size_t s = 0; s < input.sets.size(); ++s) {
    const MeasurementSet& set = input.sets[s];
    const bool bulge = set.kind == TestKind::Bulge;
    const double x0 = std::min(1.0, *std::min_element(set.x.begin(), set.x.end()));
    const double x1 = *std::max_element(set.x.begin(), set.x.end());
    std::vector<double> grid;
    for (int i = 0; i <= 80; ++i) grid.push_back(x0 + (x1 - x0) * i / 80.0);
    std::vector<std::vector<double>> curves;
    double y1 = *std::max_element(set.y.begin(), set.y.end());
    for (const FitResult& fit : outcome.fits) {
      curves.push_back(model_values(fit.material, set, grid, options));
      for (double y : curves.back())
        if (std::isfinite(y)) y1 = std::max(y1, std::min(y, 1.5 * *std::max_element(set.y.begin(), set.y.end())));
    }
    const double y0 = 0.0;
    const double top = TOP + PANEL * static_cast<double>(s), plot_w = WIDTH - LEFT - RIGHT, plot_h = PANEL - TOP - BOTTOM;
    auto px = [&](double x) { return LEFT + (x - x0) / (x1 - x0) * plot_w; };
    auto py = [&](double y) { return top + plot_h - (std::min(y, y1) - y0) / (y1 - y0) * plot_h; };
    svg << "<g>\n<text x=\"" << LEFT << "\" y=\"" << top - 10 << "\" font-weight=\"bold\">" << set.label << " ("
        << test_kind_name(set.kind) << ")</text>\n";
    svg << "<rect x=\"" << LEFT << "\" y=\"" << top << "\" width=\"" << plot_w << "\" height=\"" << plot_h
        << "\" fill=\"none\" stroke=\"black\"/>\n";
    for (int t = 0; t <= 4; ++t) {
      const double xv = x0 + (x1 - x0) * t / 4, yv = y0 + (y1 - y0) * t / 4;
      svg << "<text x=\"" << px(xv) << "\" y=\"" << top + plot_h + 16 << "\" text-anchor=\"middle\">" << number(std::round(xv * 1000) / 1000)
          << "</text>\n";
      svg << "<text x=\"" << LEFT - 6 << "\" y=\"" << py(yv) + 4 << "\" text-anchor=\"end\">" << number(std::round(yv * 1000) / 1000)
          << "</text>\n";
    }
    svg << "<text x=\"" << LEFT + plot_w / 2 << "\" y=\"" << top + plot_h + 36 << "\" text-anchor=\"middle\">"
        << (bulge ? "extension ratio sqrt(A/A0)" : "stretch") << "</text>\n";
    svg << "<text transform=\"translate(16," << top + plot_h / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
        << (bulge ? "pressure (kPa)" : "nominal stress (MPa)") << "</text>\n";
    for (size_t m = 0; m < curves.size(); ++m) {
      svg << "<polyline fill=\"none\" stroke-width=\"2\" stroke=\"" << COLORS[m % 4] << "\" points=\"";
      for (size_t i = 0; i < grid.size(); ++i)
        if (std::isfinite(curves[m][i])) svg << px(grid[i]) << "," << py(curves[m][i]) << " ";
      svg << "\"/>\n";
      svg << "<text x=\"" << LEFT + plot_w + 10 << "\" y=\"" << top + 20 + 18 * static_cast<double>(m) << "\" fill=\""
          << COLORS[m % 4] << "\">" << model_name(outcome.fits[m].material.model) << "</text>\n";
    }
    for (size_t i = 0; i < set.x.size(); ++i)
      svg << "<circle cx=\"" << px(set.x[i]) << "\" cy=\"" << py(set.y[i]) << "\" r=\"3\" fill=\"black\"/>\n";
    svg << "<text x=\"" << LEFT + plot_w + 10 << "\" y=\"" << top + 20 + 18 * static_cast<double>(curves.size())
        << "\">&#9679; data</text>\n</g>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string fit_provenance(const FitInput& input, const FitResult& fit, const std::vector<std::string>& labels) {
  std::ostringstream out;
  out.precision(4);
  out << "fitted " << utc_now_iso8601() << ", model " << model_name(fit.material.model) << ", data";
  for (size_t i = 0; i < input.sets.size(); ++i)
    out << (i ? " + " : " ") << (i < labels.size() ? labels[i] : input.sets[i].label) << " ("
        << test_kind_name(input.sets[i].kind) << ")";
  out << " sha256 " << input.data_sha256 << ", " << fit.points << " points, rms residual " << fit.rms_residual << " "
      << fit.residual_unit << ", max " << fit.max_residual << " " << fit.residual_unit;
  return out.str();
}

}  // namespace balloon::jobs
