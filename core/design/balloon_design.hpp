#pragma once
/// Inverse design (paper sec. 5): the rest shape whose inflated equilibrium is closest to a target.
/// The target must already be prepared (closed, manifold, mm; see target_preparation.hpp).
#include <optional>
#include <string>
#include <vector>

#include "design/rest_inflation_check.hpp"
#include "material/material.hpp"
#include "material/pressure_fall_band.hpp"
#include "mesh/tri_mesh.hpp"
#include "progress.hpp"

namespace balloon {

enum class DesignMethod { Adjoint, AugmentedLagrangian };

/// "adjoint" or "alm".
std::string design_method_name(DesignMethod method);

/// Why a design stopped. Only Matched and Optimal are convergence: each is a stated criterion.
enum class DesignStop {
  Matched,         ///< the average surface error fell below the match tolerance (1e-4 of the diagonal)
  Optimal,         ///< a first-order optimality measure fell below its tolerance
  Stalled,         ///< no progress: the line search found no decrease, or the error stopped falling
  TimeLimit,       ///< max_time_s ran out
  IterationLimit,  ///< max_iterations ran out
  StartFailed,     ///< the start could not be inflated (or the options were refused): no design, no errors
  Cancelled,       ///< the cancel token fired
};

/// The stop reason as one lower-case word: matched, optimal, stalled, time_limit, iteration_limit,
/// start_failed, cancelled.
std::string design_stop_name(DesignStop stop);
Result<DesignMethod> parse_design_method(const std::string& name);

/// Where an interrupted design continues: its rest shape (#V x 3, mm, the target's connectivity) after
/// `iteration` (taken from the progress events' rest_shape).
struct DesignCheckpoint {
  Positions rest;
  int iteration = 0;
};

struct DesignOptions {
  Material material;
  double thickness_mm = 0.5;            ///< rest membrane thickness (mm)
  /// How far the balloon inflates. The start is the target scaled about its centroid by
  /// `scale` when scale > 0, else by volume_ratio^(-1/3); the pressure is the one that inflates that
  /// start to the target's volume (paper sec. 5.2, "Inflation Pressure").
  double volume_ratio = 8.0;            ///< target volume / rest volume of the start
  double scale = 0.0;                   ///< linear scale of the start (0 = use volume_ratio)
  /// Optional start rest shape (#V x 3, mm, the target's connectivity) instead of the downscaled target,
  /// e.g. a perturbed one for the stability test. It is rescaled about its centroid to the rest volume
  /// that `scale` or `volume_ratio` asks for.
  Positions initial_rest;
  DesignMethod method = DesignMethod::Adjoint;
  std::vector<int> nozzle_vertices;     ///< rest vertices held at their start positions (empty = no nozzle)
  double max_time_s = 0.0;              ///< wall-time budget (s); 0 = none
  int max_iterations = 200;             ///< outer iterations
  double k_length = 1.0, k_bending = 1.0;  ///< E_dist coefficients (eq. 18)
  /// Weight of the surface term k_s L mean_i (d_i / diag)^2 (d_i: inflated vertex to target surface,
  /// mm; L: total target edge length, mm): with 100, a surface distance of 10% of the diagonal costs as
  /// much as a 100% edge strain. It targets the error the result reports, which E_dist alone trades
  /// against hinge angles (bench: bunny 2.4x -> 3.5x better than the baseline). 0 switches it off.
  double k_surface = 100.0;
  /// Continuation of the surface term (adjoint): after every `surface_growth_iterations` iterations its
  /// weight grows by `surface_growth`, up to `max_surface_growth` times k_surface. Far from the target the
  /// closest points are poor guides and E_dist's correspondence leads; near it E_dist's compromise between
  /// edge lengths and hinge angles, which no inflated sheet meets exactly, holds the surface error on a
  /// plateau unless the surface term gains weight (corpus, silicone, 40 s: median error 0.77% -> 0.59% of
  /// the diagonal). Starting at the final weight is worse (README "Design on the corpus"). 1 switches it off.
  /// Every 4 iterations rather than 8: the designs whose iterations are slow (bent sheets, 15-20 iterations
  /// in 40 s) had their weight grown once or twice (silicone corpus from rest, 40 s: median 0.43% -> 0.29%,
  /// the anchor 2.3x -> 4.1x; latex 1.39% -> 0.91%).
  double surface_growth = 3.0;
  int surface_growth_iterations = 4;
  double max_surface_growth = 1000.0;
  /// Continue from a checkpoint (adjoint only): the start is still inflated for the baseline, then the
  /// checkpoint's rest shape is brought to equilibrium and the iterations go on from its count. A
  /// checkpoint that does not fit the target or cannot be inflated is ignored (the design starts over).
  std::optional<DesignCheckpoint> resume;
  /// Coarse-to-fine (adjoint only; multiresolution_design.hpp): a target with at least twice this many
  /// vertices is first designed remeshed to about this many, where an iteration costs a sixth, and the
  /// design continues from there at full resolution. 0 (the default: measured on the corpus, the carried
  /// shape mostly could not be inflated or led to a worse stall; README "Design on the corpus") designs
  /// at full resolution only. Not used with a nozzle, a given start or a checkpoint, which name
  /// full-resolution vertices.
  int coarse_vertices = 0;
  /// The coarse stage's share of max_time_s (when there is a budget).
  double coarse_time_fraction = 0.5;
  /// After the design, inflate its rest shape from rest as `balloon simulate` does and compare
  /// (DesignResult::from_rest); costs one forward inflation, outside max_time_s.
  bool check_from_rest = true;
  int progress_mesh_every = 5;          ///< attach the inflated mesh to every K-th progress event
  ProgressCallback progress;            ///< optional; phases "start", "design"
  const CancelToken* cancel = nullptr;  ///< optional; checked between iterations
};

/// One row of the convergence log: error against run time.
struct ConvergenceSample {
  double time_s = 0.0;
  int iteration = 0;
  double avg_error_mm = 0.0;
  double max_error_mm = 0.0;
  double residual_norm = 0.0;  ///< force residual of the inflated shape (N)
};

/// The coarse stage of a coarse-to-fine design.
struct CoarseStage {
  int vertices = 0;          ///< the coarse target's vertices
  int iterations = 0;        ///< iterations run on it
  double time_s = 0.0;       ///< its wall time (s), included in the result's time_s and log
  DesignStop stop = DesignStop::StartFailed;
  /// Its average error against the coarse target (mm); none when its start was not inflated.
  std::optional<double> avg_error_mm;
  /// Its rest shape was carried to full resolution and the design went on from it there; false when the
  /// carried shape could not be inflated (or there was none) and the full-resolution design started over.
  bool carried = false;
};

/// A rest shape of the run whose inflation from rest was measured along the way: the start (its
/// inflation is the forward solver's volume path from rest) and the rest shapes checked from rest at each
/// growth of the surface weight (DesignDriver::take_pending_shape_from_rest).
struct CheckedFromRest {
  Positions rest;               ///< #V by 3 (mm)
  double avg_error_mm = 0.0;    ///< its shape from rest against the target (mm), aligned as the error is
  int iteration = 0;            ///< the design iteration it is the rest shape of (0: the start)
};

struct DesignResult {
  bool converged = false;              ///< stop is Matched or Optimal, and the returned shape is an equilibrium
  DesignStop stop = DesignStop::StartFailed;
  std::string message;                 ///< why it stopped, as a sentence
  DesignMethod method = DesignMethod::Adjoint;
  TriMesh rest;                        ///< the balloon to fabricate (mm)
  Positions inflated;                  ///< its predicted inflated shape, rigidly aligned to the target (mm)
  /// The design's inflation (kPa, inflated / rest volume); none when no start was inflated.
  std::optional<double> pressure_kpa, volume_ratio;
  int iterations = 0;
  std::optional<int> resumed_from_iteration;  ///< set when the design continued from a checkpoint
  double time_s = 0.0;
  /// Inflated vertex to target surface (mm), and over the target's bounding-box diagonal. Empty when
  /// there is no design (start_failed): a design that was never inflated has no error, not zero.
  std::optional<double> avg_error_mm, max_error_mm;
  std::optional<double> avg_error_rel, max_error_rel;
  double bbox_diag_mm = 0.0;
  /// The start (downscaled target) inflated (mm); empty when it could not be inflated.
  std::optional<double> baseline_avg_error_mm, baseline_max_error_mm;
  std::optional<double> distance_energy;  ///< E_dist at the end (mm); none without a design
  std::optional<double> residual_norm;    ///< force residual of the inflated shape (N); none without a design
  /// k_surface times its growth at the end (dimensionless; 0 when the surface term is off).
  double surface_weight = 0.0;
  /// The objective's terms and constraints that took part: "distance" always; "surface" (k_surface > 0);
  /// "fixed_rest_volume"
  /// (adjoint: the rest volume is held at target volume / ratio); "max_volume" (alm, once a rest region
  /// has turned inside out); "rest_bending" (the start has coplanar hinges); "collision" (rest vertices
  /// came within the contact distance); "nozzle" (nozzle vertices held); "sheet_bending" (the sheet's
  /// bending stiffness, switched on when the start wrinkled with no stable membrane state).
  std::vector<std::string> active_terms;
  std::vector<ConvergenceSample> log;   ///< full-resolution iterations only (times include the coarse stage)
  std::optional<CoarseStage> coarse_stage;  ///< set when the design ran coarse-to-fine
  /// The rest shape inflated from rest as `balloon simulate` does (DesignOptions::check_from_rest); none
  /// without a design or with the check off.
  std::optional<RestInflationCheck> from_rest;
  /// Of the rest shapes checked from rest during the run, the one whose shape from rest came closest to
  /// the target; none without an inflated start. Where the final design inflates from rest farther
  /// from the target, or finds no equilibrium there, this one is handed back (closest_from_rest.hpp).
  std::optional<CheckedFromRest> closest_from_rest;
  /// Where the rubber's sphere pressure falls as it stretches (material/pressure_fall_band.hpp); none
  /// when it never does.
  std::optional<PressureFallBand> pressure_fall;
  /// The share (0..1) of the handed-back inflated shape's area stretched into that band
  /// (material/pressure_fall_share.hpp); none without a design or without a band.
  std::optional<double> pressure_fall_area_share;
};

/// Designs the rest shape for `target`. Never throws for bad numerics: failures are in the result.
DesignResult design_balloon(const TriMesh& target, const DesignOptions& options);

/// The start's size against the target's (a ratio of lengths): `options.scale` when set, else the cube
/// root of 1 / `options.volume_ratio`.
double design_start_scale(const DesignOptions& options);

}  // namespace balloon
