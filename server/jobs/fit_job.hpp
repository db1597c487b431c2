#pragma once
/// The material-fit job without any transport: parse and check measurement files, fit one or all rubber
/// laws, and describe the outcome (text, JSON, SVG plot, provenance for the material library).
/// The service's fit_material job runs fits through this layer; the CLI checks data with prepare_fit and
/// reads the job's typed report back (service/job_reports: fit_outcome_from_report) to print and plot it.
#include <string>
#include <string_view>
#include <vector>

#include "material/fitting.hpp"
#include "material/material.hpp"
#include "material/measurements.hpp"
#include "result.hpp"

namespace balloon::jobs {

/// One measurement file as the user gave it.
struct FitDataFile {
  std::string label;         ///< shown in reports, e.g. the file name
  std::string csv_text;      ///< the file's bytes
  std::string test;          ///< "bulge", "uniaxial", "equibiaxial" or "pure-shear"
  double radius_mm = 0.0;    ///< bulge only: opening radius (mm), > 0
  double thickness_mm = 0.0; ///< bulge only: rest disc thickness (mm), > 0
};

/// A fit job whose inputs have all been checked.
struct FitInput {
  std::vector<MeasurementSet> sets;   ///< one per file, same order
  std::vector<MaterialModel> models;  ///< the laws to fit (one, or all three for "all")
  bool all_models = false;            ///< the user asked for "all" (reports are lists)
  std::string data_sha256;            ///< SHA-256 (hex) of the files' bytes, in order
};

/// Checks the model name ("hart-smith", "mooney-rivlin", "neo-hookean" or "all") and parses every file
/// (see parse_measurements; bulge files also need radius and thickness). The error names the file.
Result<FitInput> prepare_fit(const std::vector<FitDataFile>& files, const std::string& model);

/// A model that "all" left out because the data cannot fit it, and why.
struct FitSkip {
  MaterialModel model = MaterialModel::NeoHookean;
  std::string reason;
};

/// The fits, one per model of the input in the input's order, less the ones skipped.
struct FitOutcome {
  std::vector<FitResult> fits;
  std::vector<FitSkip> skipped;  ///< "all" only: models the data cannot fit (at least one model is fitted)
  double time_s = 0.0;  ///< wall time of all fits (s)
};

/// Fits every model. Bulge sets are simulated by the axisymmetric membrane (core/calibration/
/// axisymmetric_bulge) at their apex heights when the data has them, else at their extension ratios.
/// Fails with a message when the data cannot be fitted (e.g. fewer points than parameters); with "all",
/// only when no model can be, the others being listed in `skipped` (2 points fit Neo-Hookean and
/// Mooney-Rivlin but not Hart-Smith's 3 constants, which failed the whole command before). Fails with
/// FIT_CANCELLED once `cancel` (may be null) fires: it is checked between iterations of every fit.
Result<FitOutcome> run_fit(const FitInput& input, const CancelToken* cancel = nullptr);

/// Index into outcome.fits of the best fit (smallest RMS relative residual).
int best_fit_index(const FitOutcome& outcome);

/// One fit as a JSON object: model, spec, params (by SPEC name), std_errors, rms_residual, max_residual,
/// residual_unit, rms_relative_residual, max_relative_residual, points, converged, regimes, sets, message.
std::string fit_json(const FitResult& fit);
/// What `balloon fit-material --json` prints: one object for a single model, a list of objects for "all".
/// The (first) object also carries `plot_svg`, the fit_plot_svg of the whole outcome.
std::string fit_report_json(const FitInput& input, const FitOutcome& outcome);
/// A few human-readable lines per model, with units.
std::string fit_summary_text(const FitInput& input, const FitOutcome& outcome);
/// An SVG with one panel per measurement set: the data points and each model's curve (pressure (kPa)
/// against extension ratio for bulge sets, nominal stress (MPa) against stretch for stress tables).
std::string fit_plot_svg(const FitInput& input, const FitOutcome& outcome);
/// Provenance for the material library: data hash, model, residuals and the fit time (UTC, ISO 8601).
std::string fit_provenance(const FitInput& input, const FitResult& fit, const std::vector<std::string>& labels);

/// SHA-256 of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace balloon::jobs
