// A design or simulate report's band of falling pressure in words: where the rubber's pressure falls as it
// stretches, how much of the inflated surface is stretched there and, when most of it is, what that
// does to a balloon and which volume ratios avoid it.
import { format_number } from './format.js';

/** Above this share of the inflated surface in the band the line says what it means for the maker. */
export const PRESSURE_FALL_ADVICE_SHARE = 0.5;

/**
 * @param {object|undefined} band  DesignReport or SimulateReport pressure_fall (absent when the rubber's pressure
 *   never falls)
 * @returns {string}  one line for the job panel's summary, or '' without a band
 */
export function pressure_fall_line(band) {
  if (!band || band.from_stretch == null) return '';
  const has_end = band.to_stretch != null;
  const where = has_end
    ? `between stretch ${format_number(band.from_stretch, 4)} and ${format_number(band.to_stretch, 4)} ` +
      `(volume ratio ${format_number(band.from_volume_ratio, 3)} to ${format_number(band.to_volume_ratio, 3)})`
    : `past stretch ${format_number(band.from_stretch, 4)} (volume ratio ${format_number(band.from_volume_ratio, 3)})`;
  let line = `This rubber's pressure falls as it stretches ${where}`;
  if (band.area_share == null) return `${line}.`;
  line += `; ${format_number(100 * band.area_share, 3)} % of the inflated surface is stretched there`;
  if (band.area_share <= PRESSURE_FALL_ADVICE_SHARE) return `${line}.`;
  return `${line}: long or thin parts of a balloon there can bulge one at a time instead of inflating evenly (as a ` +
    'long party balloon does); a volume ratio below ' +
    `${format_number(band.from_volume_ratio, 3)}${has_end ? ` or above ${format_number(band.to_volume_ratio, 3)}` : ''} ` +
    'keeps the sheet out of it.';
}
