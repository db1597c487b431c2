#include "service/job_reports.hpp"

#include <algorithm>
#include <limits>

#include "service/pressure_fall_message.hpp"

namespace balloon::service {
namespace {

namespace v1 = balloon::v1;

/// a / b when both exist and b > 0; none otherwise (no baseline, no design, or a design with zero error).
std::optional<double> ratio(const std::optional<double>& a, const std::optional<double>& b) {
  if (!a || !b || !(*b > 0.0)) return std::nullopt;
  return *a / *b;
}

}  // namespace

v1::SimulateReport simulate_report(const jobs::SimulateInput& input, const InflationResult& result) {
  v1::SimulateReport report;
  report.set_converged(result.converged);
  report.set_pressure_kpa(result.pressure_kpa);
  report.set_volume_mm3(result.volume_mm3);
  report.set_rest_volume_mm3(result.rest_volume_mm3);
  report.set_volume_ratio(result.volume_ratio);
  report.set_mean_stretch(result.mean_stretch);
  report.set_max_stretch(result.max_stretch);
  report.set_newton_iterations(result.newton_iterations);
  report.set_factorizations(result.factorizations);
  report.set_load_steps(result.load_steps);
  report.set_residual_norm(result.residual_norm);
  report.set_unstable_modes(result.unstable_modes);
  report.set_bending(result.bending);
  report.set_flipped_cap_slivers(result.flipped_cap_slivers);
  report.set_time_s(result.time_s);
  report.set_vertices(input.rest.vertex_count());
  report.set_faces(input.rest.face_count());
  report.set_material(material_spec(input.material));
  report.set_material_name(input.material.name);
  report.set_thickness_mm(input.thickness_mm);
  if (input.control == InflationControl::Pressure) {
    report.set_control("pressure");
    report.set_target_pressure_kpa(input.pressure_kpa);
  } else {
    report.set_control("volume_ratio");
    report.set_target_volume_ratio(input.volume_ratio);
  }
  report.set_flipped_orientation(input.flipped_orientation);
  report.set_message(result.message);
  if (result.pressure_fall)
    fill_pressure_fall(*result.pressure_fall, result.pressure_fall_area_share, *report.mutable_pressure_fall());
  report.set_stop_reason(inflation_stop_word(result.stop));
  return report;
}

v1::CurveReport curve_report(const jobs::SimulateInput& input, const PressureVolumeCurve& curve) {
  v1::CurveReport report;
  report.set_converged(curve.converged);
  report.set_stop_reason(inflation_stop_word(curve.stop));
  report.set_message(curve.message);
  if (input.curve) {
    report.set_control(input.curve->control == InflationControl::Pressure ? "pressure" : "volume_ratio");
    report.set_range_from(input.curve->from);
    report.set_range_to(input.curve->to);
    report.set_points_requested(input.curve->points);
  }
  for (const CurvePoint& point : curve.points) {
    v1::CurvePointReport* row = report.add_points();
    row->set_target(point.target);
    row->set_converged(point.converged);
    if (point.volume_ratio) row->set_volume_ratio(*point.volume_ratio);
    if (point.pressure_kpa) row->set_pressure_kpa(*point.pressure_kpa);
    if (point.mean_stretch) row->set_mean_stretch(*point.mean_stretch);
    if (point.max_stretch) row->set_max_stretch(*point.max_stretch);
    if (point.unstable_modes) row->set_unstable_modes(*point.unstable_modes);
    row->set_message(point.message);
  }
  for (const CurveExtremum& extremum : curve.extrema) {
    v1::CurveExtremumReport* row = report.add_extrema();
    row->set_kind(extremum.maximum ? "maximum" : "minimum");
    row->set_point(extremum.point);
    row->set_volume_ratio(extremum.volume_ratio);
    row->set_pressure_kpa(extremum.pressure_kpa);
  }
  report.set_rest_volume_mm3(curve.rest_volume_mm3);
  report.set_newton_iterations(curve.newton_iterations);
  report.set_factorizations(curve.factorizations);
  report.set_load_steps(curve.load_steps);
  report.set_time_s(curve.time_s);
  report.set_vertices(input.rest.vertex_count());
  report.set_faces(input.rest.face_count());
  report.set_material(material_spec(input.material));
  report.set_material_name(input.material.name);
  report.set_thickness_mm(input.thickness_mm);
  report.set_flipped_orientation(input.flipped_orientation);
  report.set_last_converged_point(curve.last_converged_point);
  report.set_bending(curve.bending);
  report.set_flipped_cap_slivers(curve.flipped_cap_slivers);
  return report;
}

v1::DesignReport design_report(const jobs::DesignInput& input, const jobs::DesignOutcome& outcome) {
  const DesignResult& result = outcome.result;
  const PreparedTarget& target = input.target;
  v1::DesignReport report;
  report.set_converged(result.converged);
  report.set_stop_reason(design_stop_name(result.stop));
  report.set_method(design_method_name(result.method));
  if (const std::optional<double> value = result.avg_error_mm) report.set_avg_error_mm(*value);
  if (const std::optional<double> value = result.max_error_mm) report.set_max_error_mm(*value);
  if (const std::optional<double> value = result.avg_error_rel) report.set_avg_error_rel(*value);
  if (const std::optional<double> value = result.max_error_rel) report.set_max_error_rel(*value);
  report.set_bbox_diag_mm(result.bbox_diag_mm);
  if (const std::optional<double> value = result.pressure_kpa) report.set_pressure_kpa(*value);
  if (const std::optional<double> value = result.volume_ratio) report.set_volume_ratio(*value);
  report.set_iterations(result.iterations);
  report.set_time_s(result.time_s);
  report.set_vertices(result.rest.vertex_count());
  report.set_faces(result.rest.face_count());
  for (const std::string& term : result.active_terms) report.add_active_terms(term);
  if (const std::optional<double> value = result.baseline_avg_error_mm) report.set_baseline_avg_error_mm(*value);
  if (const std::optional<double> value = result.baseline_max_error_mm) report.set_baseline_max_error_mm(*value);
  if (const std::optional<double> value = ratio(result.baseline_avg_error_mm, result.bbox_diag_mm))
    report.set_baseline_avg_error_rel(*value);
  if (const std::optional<double> value = ratio(result.baseline_avg_error_mm, result.avg_error_mm))
    report.set_improvement_over_baseline(*value);
  if (const std::optional<double> value = result.distance_energy) report.set_distance_energy(*value);
  if (const std::optional<double> value = result.residual_norm) report.set_residual_norm(*value);
  report.set_surface_weight(result.surface_weight);
  report.set_material(material_spec(input.material));
  report.set_material_name(input.material.name);
  report.set_thickness_mm(input.parameters.thickness_mm);
  report.set_start_scale(input.start_scale);
  report.set_max_time_s(input.parameters.max_time_s);
  report.set_cancelled(outcome.cancelled);
  report.set_message(result.message);
  if (result.resumed_from_iteration) report.set_resumed_from_iteration(*result.resumed_from_iteration);

  v1::TargetPreparation* preparation = report.mutable_preparation();
  preparation->set_summary(target.summary);
  preparation->set_scale_factor(target.scale_factor);
  preparation->set_reoriented(target.reoriented);
  preparation->set_unreferenced_vertices_removed(target.unreferenced_vertices_removed);
  preparation->set_remeshed(target.remeshed);
  preparation->set_vertices_before(target.vertices_before);
  preparation->set_vertices_after(target.vertices_after);
  preparation->set_faces_before(target.faces_before);
  preparation->set_faces_after(target.faces_after);
  preparation->set_min_angle_before_deg(target.min_angle_before_deg);
  preparation->set_min_angle_after_deg(target.min_angle_after_deg);
  preparation->set_target_edge_length_mm(target.target_edge_length_mm);
  preparation->set_bbox_diag_mm(target.bbox_diag_mm);
  preparation->set_volume_mm3(target.volume_mm3);
  preparation->set_self_intersecting(target.self_intersecting);

  v1::DesignNozzle* nozzle = report.mutable_nozzle();
  nozzle->set_requested(input.parameters.nozzle);
  if (input.nozzle) {
    nozzle->set_center_vertex(input.nozzle->center_vertex);
    nozzle->set_radius_mm(input.nozzle->radius_mm);
    nozzle->set_fixed_vertices(static_cast<int>(input.nozzle->vertices.size()));
  }

  if (outcome.mold) {
    report.mutable_mold()->set_nozzle_vertex(outcome.mold->nozzle_vertex);
    report.mutable_mold()->set_tube_radius_mm(outcome.mold->tube_radius_mm);
    report.mutable_mold()->set_tube_length_mm(outcome.mold->tube_length_mm);
  } else {
    report.set_mold_problem(outcome.mold_problem);
  }

  if (outcome.tolerance) {
    v1::ToleranceReport* tolerance = report.mutable_tolerance();
    tolerance->set_samples(input.parameters.tolerance_samples);
    tolerance->set_seed(jobs::TOLERANCE_SEED);
    tolerance->set_control("volume_ratio");
    for (const ThicknessToleranceLevel& level : outcome.tolerance->levels) {
      v1::ToleranceLevel* out = tolerance->add_levels();
      out->set_perturbation(level.perturbation);
      out->set_mean_deviation_mm(level.mean_deviation_mm);
      out->set_max_deviation_mm(level.max_deviation_mm);
      out->set_samples(level.samples);
      out->set_failed_samples(level.failed_samples);
    }
  }

  if (const std::optional<RestInflationCheck>& check = result.from_rest) {
    v1::RestInflationCheck* out = report.mutable_from_rest();
    out->set_converged(check->converged);
    out->set_stop_reason(inflation_stop_word(check->stop));
    out->set_message(check->message);
    if (check->avg_error_mm) out->set_avg_error_mm(*check->avg_error_mm);
    if (check->max_error_mm) out->set_max_error_mm(*check->max_error_mm);
    if (check->avg_error_rel) out->set_avg_error_rel(*check->avg_error_rel);
    if (check->pressure_kpa) out->set_pressure_kpa(*check->pressure_kpa);
    out->set_unstable_modes(check->unstable_modes);
    if (check->deviation_mm) out->set_deviation_mm(*check->deviation_mm);
    out->set_another_shape(check->another_shape);
    out->set_time_s(check->time_s);
  }

  if (result.pressure_fall)
    fill_pressure_fall(*result.pressure_fall, result.pressure_fall_area_share, *report.mutable_pressure_fall());

  v1::ConvergenceLog* log = report.mutable_convergence();
  for (const ConvergenceSample& sample : result.log) {
    log->add_time_s(sample.time_s);
    log->add_iteration(sample.iteration);
    log->add_avg_error_mm(sample.avg_error_mm);
    log->add_max_error_mm(sample.max_error_mm);
    log->add_residual_norm(sample.residual_norm);
  }
  return report;
}

v1::FitReport fit_report(const jobs::FitInput& input, const jobs::FitOutcome& outcome) {
  v1::FitReport report;
  for (const FitResult& fit : outcome.fits) {
    v1::FitModelReport* out = report.add_fits();
    out->set_model(model_name(fit.material.model));
    out->set_spec(material_spec(fit.material));
    const std::vector<std::string> names = parameter_names(fit.material.model);
    for (size_t i = 0; i < names.size() && i < fit.material.params.size(); ++i)
      (*out->mutable_params())[names[i]] = fit.material.params[i];
    for (size_t i = 0; i < names.size() && i < fit.std_errors.size(); ++i)
      (*out->mutable_std_errors())[names[i]] = fit.std_errors[i];
    out->set_rms_residual(fit.rms_residual);
    out->set_max_residual(fit.max_residual);
    out->set_residual_unit(fit.residual_unit);
    out->set_rms_relative_residual(fit.rms_relative_residual);
    out->set_max_relative_residual(fit.max_relative_residual);
    out->set_points(fit.points);
    out->set_converged(fit.converged);
    out->mutable_regimes()->set_data_inflection(fit.data_inflection);
    out->mutable_regimes()->set_data_stiffening(fit.data_stiffening);
    out->mutable_regimes()->set_model_inflection(fit.model_inflection);
    out->mutable_regimes()->set_model_stiffening(fit.model_stiffening);
    for (const SetFit& set : fit.sets) {
      v1::FitSetReport* set_out = out->add_sets();
      set_out->set_label(set.label);
      set_out->set_test(test_kind_name(set.kind));
      set_out->set_points(set.points);
      set_out->set_dropped_compression_points(set.dropped_compression_points);
      set_out->set_rms_residual(set.rms_residual);
      set_out->set_max_residual(set.max_residual);
      set_out->set_residual_unit(set.residual_unit);
    }
    out->set_message(fit.message);
  }
  if (!outcome.fits.empty()) report.set_best_fit(jobs::best_fit_index(outcome));
  report.set_plot_svg(jobs::fit_plot_svg(input, outcome));
  for (const jobs::FitSkip& skip : outcome.skipped) {
    v1::FitSkipped* out = report.add_skipped();
    out->set_model(model_name(skip.model));
    out->set_reason(skip.reason);
  }
  return report;
}

Result<jobs::FitOutcome> fit_outcome_from_report(const jobs::FitInput& input, const v1::FitReport& report) {
  jobs::FitOutcome outcome;
  // The models fitted: those asked for, in order, less the ones the report says were skipped.
  std::vector<MaterialModel> fitted_models;
  for (const MaterialModel model : input.models) {
    const auto skipped = std::find_if(report.skipped().begin(), report.skipped().end(),
                                      [&](const v1::FitSkipped& skip) { return skip.model() == model_name(model); });
    if (skipped == report.skipped().end()) {
      fitted_models.push_back(model);
    } else {
      outcome.skipped.push_back({model, skipped->reason()});
    }
  }
  if (static_cast<size_t>(report.fits_size()) != fitted_models.size() ||
      outcome.skipped.size() != static_cast<size_t>(report.skipped_size()))
    return fail("the fit report has " + std::to_string(report.fits_size()) + " fit(s) and " +
                std::to_string(report.skipped_size()) + " skipped, " + std::to_string(input.models.size()) +
                " were asked for");
  for (int m = 0; m < report.fits_size(); ++m) {
    const v1::FitModelReport& in = report.fits(m);
    const MaterialModel model = fitted_models[static_cast<size_t>(m)];
    if (in.model() != model_name(model))
      return fail("the fit report's model '" + in.model() + "' is not the " + model_name(model) + " fit asked for");
    FitResult fit;
    fit.material.model = model;
    const std::vector<std::string> names = parameter_names(model);
    for (size_t i = 0; i < names.size() && i < fit.material.params.size(); ++i) {
      const auto value = in.params().find(names[i]);
      if (value == in.params().end()) return fail("the fit report lacks the constant '" + names[i] + "'");
      fit.material.params[i] = value->second;
      if (const auto error = in.std_errors().find(names[i]); error != in.std_errors().end())
        fit.std_errors.push_back(error->second);
    }
    fit.rms_residual = in.rms_residual();
    fit.max_residual = in.max_residual();
    fit.residual_unit = in.residual_unit();
    fit.rms_relative_residual = in.rms_relative_residual();
    fit.max_relative_residual = in.max_relative_residual();
    fit.points = in.points();
    fit.converged = in.converged();
    fit.message = in.message();
    fit.data_inflection = in.regimes().data_inflection();
    fit.data_stiffening = in.regimes().data_stiffening();
    fit.model_inflection = in.regimes().model_inflection();
    fit.model_stiffening = in.regimes().model_stiffening();
    if (static_cast<size_t>(in.sets_size()) != input.sets.size())
      return fail("the fit report's sets do not match the data sent");
    for (size_t s = 0; s < input.sets.size(); ++s) {
      const v1::FitSetReport& set_in = in.sets(static_cast<int>(s));
      SetFit set;
      // Labels and tests come from the local input: the service sees no file names.
      set.label = input.sets[s].label;
      set.kind = input.sets[s].kind;
      set.points = set_in.points();
      set.dropped_compression_points = set_in.dropped_compression_points();
      set.rms_residual = set_in.rms_residual();
      set.max_residual = set_in.max_residual();
      set.residual_unit = set_in.residual_unit();
      fit.sets.push_back(std::move(set));
    }
    outcome.fits.push_back(std::move(fit));
  }
  return outcome;
}

}  // namespace balloon::service
