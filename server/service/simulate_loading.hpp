#pragma once
/// Decoding and checking a SimulateJob, shared by the kinds that run one: simulate (one equilibrium)
/// and curve (the pressure-volume curve, SimulateJob.curve).
#include <optional>
#include <string>

#include "balloon/v1/balloon.pb.h"
#include "jobs/simulate_job.hpp"
#include "service/job_kind.hpp"
#include "service/material_handler.hpp"
#include "service/service_status.hpp"

namespace balloon::service {

/// Decodes and checks a simulate job (mesh within `max_vertices`, 0 = no limit; material; parameters,
/// each bad one by its field) into `loaded`.
ServiceStatus load_simulate(const balloon::v1::SimulateJob& job, const std::string& tenant, int max_vertices,
                            MaterialHandler& materials, std::optional<jobs::SimulateInput>* loaded);

/// The submit-time check of either kind: load_simulate for the caller (errors under "simulate."), and
/// the spec to store with a stored material's name replaced by its SPEC, so that editing the library
/// cannot change a queued job. The kind adds its summary (and what it hands to the run).
ServiceStatus check_simulate_spec(const balloon::v1::JobSpec& spec, const CheckContext& context, CheckedJob* checked,
                                  std::optional<jobs::SimulateInput>* input);

}  // namespace balloon::service
