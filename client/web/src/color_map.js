// Distance -> colour for the error colouring of the inflated shape: a perceptually ordered ramp
// (viridis key colours: dark blue for "on target" to yellow for "far off").

/** Key colours (sRGB, 0..1) at equal steps from 0 to 1. */
const STOPS = [
  [0.267, 0.005, 0.329],
  [0.229, 0.322, 0.546],
  [0.128, 0.567, 0.551],
  [0.369, 0.789, 0.383],
  [0.993, 0.906, 0.144],
];

/**
 * The ramp's colour at t.
 * @param {number} t  0..1 (clamped)
 * @returns {number[]}  [r, g, b] in 0..1 (sRGB)
 */
export function ramp_color(t) {
  const clamped = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0));
  const position = clamped * (STOPS.length - 1);
  const lower = Math.min(STOPS.length - 2, Math.floor(position));
  const fraction = position - lower;
  const a = STOPS[lower];
  const b = STOPS[lower + 1];
  return [a[0] + (b[0] - a[0]) * fraction, a[1] + (b[1] - a[1]) * fraction, a[2] + (b[2] - a[2]) * fraction];
}

/** A CSS linear-gradient of the ramp, left (0) to right (1), for the legend. */
export function ramp_css_gradient() {
  const parts = STOPS.map((stop, i) => {
    const [r, g, b] = stop.map((channel) => Math.round(channel * 255));
    return `rgb(${r}, ${g}, ${b}) ${(100 * i) / (STOPS.length - 1)}%`;
  });
  return `linear-gradient(to right, ${parts.join(', ')})`;
}

/** Round legend ends within one decade; close enough that the ramp's top colour is nearly used. */
const NICE_STEPS = [1, 1.5, 2, 3, 4, 5, 6, 8, 10];

/**
 * A round upper end for the legend: the smallest of 1, 1.5, 2, 3, 4, 5, 6, 8 x 10^k not below `value`.
 * @param {number} value  > 0 (mm)
 * @returns {number}
 */
export function nice_upper_bound(value) {
  if (!(value > 0) || !Number.isFinite(value)) return 1;
  const power = Math.pow(10, Math.floor(Math.log10(value)));
  for (const step of NICE_STEPS)
    if (step * power >= value * (1 - 1e-9)) return Number((step * power).toPrecision(6));
  return 10 * power;
}

/**
 * Per-vertex colours for distances.
 * @param {Float32Array} distances  #V distances (mm)
 * @param {number} upper_mm  distance drawn in the ramp's last colour (mm)
 * @returns {Float32Array}  #V x 3 colours (sRGB, 0..1)
 */
export function colors_for_distances(distances, upper_mm) {
  const colors = new Float32Array(distances.length * 3);
  for (let i = 0; i < distances.length; ++i) colors.set(ramp_color(distances[i] / upper_mm), 3 * i);
  return colors;
}
