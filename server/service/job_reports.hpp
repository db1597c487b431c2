#pragma once
/// The typed reports of finished jobs (balloon.v1.SimulateReport, DesignReport, FitReport) made from the
/// jobs layer's outcomes, and a fit report read back into fits (the CLI prints and plots a service fit).
/// The one place the report's fields are filled; proto/contract/report_json writes them as report.json.
#include "balloon/v1/balloon.pb.h"
#include "jobs/design_job.hpp"
#include "jobs/fit_job.hpp"
#include "jobs/simulate_job.hpp"
#include "result.hpp"

namespace balloon::service {

/// The report of a finished simulation of `input`.
balloon::v1::SimulateReport simulate_report(const jobs::SimulateInput& input, const InflationResult& result);

/// The report of a finished pressure-volume curve of `input` (input.curve set); values never computed
/// stay unset.
balloon::v1::CurveReport curve_report(const jobs::SimulateInput& input, const PressureVolumeCurve& curve);

/// The report of a finished design of `input`; design errors that were never computed stay unset.
balloon::v1::DesignReport design_report(const jobs::DesignInput& input, const jobs::DesignOutcome& outcome);

/// The report of a finished fit, with the plot of every set and model (fit_plot_svg).
balloon::v1::FitReport fit_report(const jobs::FitInput& input, const jobs::FitOutcome& outcome);

/// The fits of `report`, for a client that ran the fit as a service job: `input` is the same job's input
/// (checked locally), which gives each fit its model and each set its label and test. Fails on a report
/// that does not match the input (another number of fits or sets, another model, a missing constant).
Result<jobs::FitOutcome> fit_outcome_from_report(const jobs::FitInput& input, const balloon::v1::FitReport& report);

}  // namespace balloon::service
