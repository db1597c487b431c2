// The pressure-volume curve of a designed balloon, as a curve job: the design's rest shape, its rubber as
// the SPEC the design ran with, and its thickness, inflated under volume control from just above the rest
// volume to twice the design's volume ratio. The maker sees where the balloon snaps (a pressure maximum)
// and how far past the design point it holds.

/** Equilibria along the curve (the server allows 2..1000). */
export const CURVE_POINTS = 40;
/** First volume ratio of the curve (V / V_rest). */
export const CURVE_FIRST_RATIO = 1.01;
/** The curve ends at this multiple of the design's volume ratio... */
export const CURVE_RATIO_FACTOR = 2;
/** ...but not beyond this volume ratio (latex bursts long before). */
export const CURVE_LAST_RATIO_CAP = 125;

/**
 * The SubmitJob spec of the curve of a completed design.
 * @param {object} result  the design job's JobResult (the gateway's JSON mapping)
 * @returns {{simulate: object}}
 * @throws {Error} when the result holds no designed balloon (no rest mesh, or its start never inflated)
 */
export function curve_spec_for_design(result) {
  const report = result?.design_report;
  const rest = result?.rest_mesh;
  if (!report || !rest?.data) throw new Error('this job holds no designed balloon');
  const ratio = Number(report.volume_ratio);
  if (!(ratio > CURVE_FIRST_RATIO)) throw new Error('the design has no inflation: its start was never inflated');
  if (!report.material) throw new Error('the design report names no material');
  return {
    simulate: {
      rest_mesh: { data: rest.data, format: rest.format || 'obj' },
      material: { spec: report.material },
      thickness_mm: report.thickness_mm,
      curve: {
        volume_ratio_range: { from: CURVE_FIRST_RATIO, to: Math.min(CURVE_RATIO_FACTOR * ratio, CURVE_LAST_RATIO_CAP) },
        points: CURVE_POINTS,
      },
    },
  };
}
