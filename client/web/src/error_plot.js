// The live plot of the design's average distance to the target (mm) against time (s), as SVG.
// Points come from progress events while a job runs, or from the report's convergence log afterwards.

const SVG_NS = 'http://www.w3.org/2000/svg';
const WIDTH = 560;
const HEIGHT = 230;
const MARGIN = { left: 62, right: 16, top: 14, bottom: 42 };

/** About `count` round tick values (1, 2, 5 x 10^k steps) covering 0..upper. */
function ticks(upper, count = 5) {
  const raw_step = upper / count;
  const power = Math.pow(10, Math.floor(Math.log10(raw_step)));
  const step = [1, 2, 5, 10].map((m) => m * power).find((candidate) => candidate >= raw_step) ?? 10 * power;
  const values = [];
  for (let value = 0; value <= upper * (1 + 1e-9); value += step) values.push(Number(value.toPrecision(12)));
  return values;
}

/** A short label for a tick value. */
function tick_label(value) {
  if (value === 0) return '0';
  const magnitude = Math.abs(value);
  if (magnitude >= 1000 || magnitude < 1e-3) return value.toExponential(1);
  return String(Number(value.toPrecision(4)));
}

function svg_element(name, attributes = {}, text = null) {
  const element = document.createElementNS(SVG_NS, name);
  for (const [key, value] of Object.entries(attributes)) element.setAttribute(key, String(value));
  if (text !== null) element.textContent = text;
  return element;
}

export class ErrorPlot {
  /** @param {SVGSVGElement} svg  the element to draw into (its content is replaced) */
  constructor(svg) {
    this.m_svg = svg;
    this.m_times = [];
    this.m_errors = [];
    this.m_draw_pending = false;
    svg.setAttribute('viewBox', `0 0 ${WIDTH} ${HEIGHT}`);
    svg.setAttribute('role', 'img');
    this.draw();
  }

  /** Number of points plotted. */
  get point_count() {
    return this.m_times.length;
  }

  /** Forgets every point. */
  reset() {
    this.m_times = [];
    this.m_errors = [];
    this.request_draw();
  }

  /**
   * Adds one sample.
   * @param {number} time_s  time since the run started (s)
   * @param {number} avg_error_mm  average distance to the target (mm); ignored when negative (not applicable)
   */
  add_point(time_s, avg_error_mm) {
    if (!(avg_error_mm >= 0) || !Number.isFinite(time_s)) return;
    this.m_times.push(time_s);
    this.m_errors.push(avg_error_mm);
    this.request_draw();
  }

  /**
   * Replaces the points with a whole log (parallel arrays).
   * @param {number[]} times_s  (s)
   * @param {number[]} avg_errors_mm  (mm)
   */
  set_points(times_s, avg_errors_mm) {
    this.m_times = [];
    this.m_errors = [];
    const count = Math.min(times_s.length, avg_errors_mm.length);
    for (let i = 0; i < count; ++i) this.add_point(times_s[i], avg_errors_mm[i]);
    this.request_draw();
  }

  request_draw() {
    if (this.m_draw_pending) return;
    this.m_draw_pending = true;
    requestAnimationFrame(() => {
      this.m_draw_pending = false;
      this.draw();
    });
  }

  draw() {
    const svg = this.m_svg;
    while (svg.firstChild) svg.removeChild(svg.firstChild);
    svg.dataset.points = String(this.m_times.length);
    const plot_width = WIDTH - MARGIN.left - MARGIN.right;
    const plot_height = HEIGHT - MARGIN.top - MARGIN.bottom;
    const x_upper = Math.max(1, ...this.m_times);
    const y_upper = this.m_errors.length > 0 ? Math.max(...this.m_errors) * 1.05 : 1;
    const x_ticks = ticks(x_upper);
    const y_ticks = ticks(y_upper > 0 ? y_upper : 1, 4);
    const x_max = x_ticks[x_ticks.length - 1] >= x_upper ? x_ticks[x_ticks.length - 1] : x_upper;
    const y_max = y_ticks[y_ticks.length - 1] >= y_upper ? y_ticks[y_ticks.length - 1] : y_upper;
    const x_of = (t) => MARGIN.left + (t / x_max) * plot_width;
    const y_of = (e) => MARGIN.top + plot_height - (e / y_max) * plot_height;

    const axes = svg_element('g', { class: 'plot-axes' });
    for (const value of y_ticks) {
      axes.appendChild(svg_element('line', { x1: MARGIN.left, x2: MARGIN.left + plot_width, y1: y_of(value), y2: y_of(value), class: 'plot-grid' }));
      axes.appendChild(svg_element('text', { x: MARGIN.left - 6, y: y_of(value) + 4, 'text-anchor': 'end' }, tick_label(value)));
    }
    for (const value of x_ticks) {
      axes.appendChild(svg_element('line', { x1: x_of(value), x2: x_of(value), y1: MARGIN.top + plot_height, y2: MARGIN.top + plot_height + 4, class: 'plot-tick' }));
      axes.appendChild(svg_element('text', { x: x_of(value), y: MARGIN.top + plot_height + 17, 'text-anchor': 'middle' }, tick_label(value)));
    }
    axes.appendChild(svg_element('rect', { x: MARGIN.left, y: MARGIN.top, width: plot_width, height: plot_height, class: 'plot-frame' }));
    axes.appendChild(svg_element('text', { x: MARGIN.left + plot_width / 2, y: HEIGHT - 6, 'text-anchor': 'middle', class: 'plot-label' }, 'time (s)'));
    axes.appendChild(svg_element('text', {
      x: 14, y: MARGIN.top + plot_height / 2, 'text-anchor': 'middle', class: 'plot-label',
      transform: `rotate(-90 14 ${MARGIN.top + plot_height / 2})`,
    }, 'average error (mm)'));
    svg.appendChild(axes);

    if (this.m_times.length === 0) {
      svg.appendChild(svg_element('text', { x: MARGIN.left + plot_width / 2, y: MARGIN.top + plot_height / 2, 'text-anchor': 'middle', class: 'plot-empty' }, 'No data yet: start a design to see its error fall.'));
      return;
    }
    const points = this.m_times.map((t, i) => `${x_of(t).toFixed(1)},${y_of(this.m_errors[i]).toFixed(1)}`).join(' ');
    svg.appendChild(svg_element('polyline', { points, class: 'plot-line' }));
    const last = this.m_times.length - 1;
    svg.appendChild(svg_element('circle', { cx: x_of(this.m_times[last]), cy: y_of(this.m_errors[last]), r: 3.5, class: 'plot-last' }));
  }
}
