// A curve job's report in words: how many equilibria converged over which range, and each pressure
// extremum with what it means for the maker.
import { format_number } from './format.js';

/**
 * @param {object} report  a CurveReport (the gateway's JSON mapping; values never computed are absent)
 * @returns {string[]}  lines for the job panel's summary
 */
export function curve_summary_lines(report) {
  const points = Array.isArray(report.points) ? report.points : [];
  const converged = points.filter((point) => point.converged).length;
  const by_pressure = report.control === 'pressure';
  const unit = by_pressure ? ' kPa' : '';
  const what = by_pressure ? 'pressure' : 'volume ratio';
  const lines = [`${converged} of ${points.length} equilibria converged, ${what} ${format_number(report.range_from)}` +
    `${unit} to ${format_number(report.range_to)}${unit}; ${report.vertices ?? '?'} vertices; ` +
    `${report.material_name || report.material || ''}, ${format_number(report.thickness_mm, 3)} mm thick.`];
  const extrema = Array.isArray(report.extrema) ? report.extrema : [];
  for (const extremum of extrema) {
    const where = `${format_number(extremum.pressure_kpa)} kPa at volume ratio ${format_number(extremum.volume_ratio)}`;
    lines.push(extremum.kind === 'maximum'
      ? `Pressure maximum: ${where}. Inflated by pressure, the balloon snaps past it; by volume (a pump), it goes on.`
      : `Pressure minimum: ${where}. Past it the pressure rises again.`);
  }
  if (converged > 1 && !extrema.some((extremum) => extremum.kind === 'maximum')) {
    const span = converged === points.length ? 'over this range' : 'up to where the curve stopped';
    lines.push(`No pressure maximum ${span}: the pressure rises all the way, so inflating by pressure is stable there.`);
  }
  return lines;
}
