// Plain-words text for the page: numbers with sensible precision, job states and kinds, timestamps.

/**
 * A number for a readout, or '–' when it is missing or not applicable (negative where -1 means n/a).
 * @param {number} value
 * @param {number} [significant]  significant digits
 * @returns {string}
 */
export function format_number(value, significant = 4) {
  if (value === null || value === undefined || !Number.isFinite(Number(value))) return '–';
  const number = Number(value);
  if (number === 0) return '0';
  const magnitude = Math.abs(number);
  if (magnitude >= 1e6 || magnitude < 1e-4) return number.toExponential(significant - 1);
  return String(Number(number.toPrecision(significant)));
}

/** A distance readout (mm) where -1 means "not applicable". */
export function format_error_mm(value) {
  // null (never computed) must not read as 0: Number(null) is 0.
  return value !== null && value !== undefined && Number(value) >= 0 ? format_number(value) : '–';
}

const STATE_LABELS = {
  JOB_STATE_QUEUED: 'Queued',
  JOB_STATE_RUNNING: 'Running',
  JOB_STATE_COMPLETED: 'Completed',
  JOB_STATE_FAILED: 'Failed',
  JOB_STATE_CANCELLED: 'Cancelled',
};

/** "JOB_STATE_RUNNING" -> "Running". */
export function state_label(state) {
  return STATE_LABELS[state] ?? 'Unknown';
}

/** CSS modifier for a state badge: "queued", "running", ... */
export function state_class(state) {
  return (STATE_LABELS[state] ?? 'unknown').toLowerCase();
}

/** Whether a job in this state may still change (so it can be watched and cancelled). */
export function is_active_state(state) {
  return state === 'JOB_STATE_QUEUED' || state === 'JOB_STATE_RUNNING';
}

const KIND_LABELS = {
  JOB_KIND_SIMULATE: 'simulate',
  JOB_KIND_DESIGN: 'design',
  JOB_KIND_FIT_MATERIAL: 'material fit',
  JOB_KIND_CURVE: 'curve',
};

/** "JOB_KIND_DESIGN" -> "design". */
export function kind_label(kind) {
  return KIND_LABELS[kind] ?? 'job';
}

/**
 * A timestamp (ms since the epoch, as the JSON mapping's int64 string) in the viewer's local time.
 * @param {string|number} ms
 * @returns {string}
 */
export function format_timestamp(ms) {
  const number = Number(ms);
  if (!(number > 0)) return '–';
  const date = new Date(number);
  const today = new Date();
  const same_day = date.toDateString() === today.toDateString();
  return same_day ? date.toLocaleTimeString() : date.toLocaleString();
}
