// "Fit a new material": sends a CSV of measurements as a fit_material job, waits for it, then shows
// the fit plot (files/fit.svg) and the fitted constants, and hands the stored name to the material list.
import { base64_from_bytes } from './api_client.js';
import { show_error, show_field_errors } from './field_errors.js';
import { format_number, state_label } from './format.js';
import { ordered_params, param_label } from './material_params.js';

const NAME_PATTERN = /^[A-Za-z0-9._-]{1,64}$/;

export class FitPanel {
  /**
   * @param {import('./api_client.js').ApiClient} api
   * @param {object} elements  details, csv, csv_error, test, bulge_fields, radius, thickness, model, name,
   *   name_error, start, status, error, result, plot, constants
   * @param {(name: string) => void} on_material_stored  called with the new material's name
   */
  constructor(api, elements, on_material_stored) {
    this.m_api = api;
    this.m_elements = elements;
    this.m_on_material_stored = on_material_stored;
    this.m_plot_url = null;
    elements.test.addEventListener('change', () => {
      elements.bulge_fields.hidden = elements.test.value !== 'bulge';
    });
    elements.start.addEventListener('click', () => this.start());
  }

  clear_messages() {
    for (const key of ['csv_error', 'name_error', 'error']) show_error(this.m_elements[key], '');
    this.m_elements.status.textContent = '';
  }

  /** Shows a refused fit under the inputs its bad fields name (by path); the rest below the button. */
  show_service_error(error) {
    const unplaced = show_field_errors(this.m_elements.details, error.fields ?? []);
    if (unplaced.length > 0) show_error(this.m_elements.error, unplaced.map((violation) => violation.description).join(' '));
    else if (!(error.fields?.length > 0)) show_error(this.m_elements.error, error.message);
  }

  async start() {
    const elements = this.m_elements;
    this.clear_messages();
    const file = elements.csv.files?.[0];
    const name = elements.name.value.trim();
    let ok = true;
    if (!file) {
      show_error(elements.csv_error, 'Choose a CSV file of measurements first.');
      ok = false;
    }
    if (!NAME_PATTERN.test(name)) {
      show_error(elements.name_error, 'Give the material a name of 1-64 letters, digits, dots, dashes or underscores.');
      ok = false;
    }
    if (!ok) return;

    const set = { csv: base64_from_bytes(await file.arrayBuffer()), test: elements.test.value, label: file.name };
    if (set.test === 'bulge') {
      set.radius_mm = Number(elements.radius.value);
      set.thickness_mm = Number(elements.thickness.value);
    }
    const spec = { fit_material: { data: [set], model: elements.model.value, name } };
    elements.start.disabled = true;
    try {
      const job = await this.m_api.submit_job(spec);
      elements.status.textContent = `Fitting (job ${job.id}): ${state_label(job.state).toLowerCase()}…`;
      await this.m_api.watch_job(job.id, (event) => {
        elements.status.textContent = `Fitting (job ${job.id}): ${state_label(event.state).toLowerCase()}…`;
      });
      const finished = await this.m_api.get_job(job.id);
      if (finished.state !== 'JOB_STATE_COMPLETED') {
        elements.status.textContent = '';
        show_error(elements.error, `The fit ${state_label(finished.state).toLowerCase()}: ${finished.error || 'no reason given'}`);
        return;
      }
      await this.show_result(job.id);
      elements.status.textContent = `Stored as “${name}” and chosen as the design's material.`;
      this.m_on_material_stored(name);
    } catch (error) {
      elements.status.textContent = '';
      this.show_service_error(error);
    } finally {
      elements.start.disabled = false;
    }
  }

  /**
   * Shows a finished fit job: its plot and constants. Also used when a fit job is reopened.
   * @param {string} job_id
   */
  async show_result(job_id) {
    const elements = this.m_elements;
    elements.details.open = true;
    const result = await this.m_api.get_result(job_id);
    const fits = result.fit_report?.fits ?? [];
    const table = elements.constants;
    table.replaceChildren();
    const header = table.insertRow();
    for (const text of ['model', 'constants', 'RMS residual', 'points']) {
      const cell = document.createElement('th');
      cell.textContent = text;
      header.appendChild(cell);
    }
    for (const fit of fits) {
      const row = table.insertRow();
      row.insertCell().textContent = fit.model ?? '?';
      row.insertCell().textContent = ordered_params(fit.params)
        .map(([name, value]) => `${param_label(name)} = ${format_number(value, 5)}`)
        .join('\n');
      row.insertCell().textContent = `${format_number(fit.rms_residual, 3)} ${fit.residual_unit ?? ''} ` +
        `(${format_number(100 * (fit.rms_relative_residual ?? NaN), 3)} %)`;
      row.insertCell().textContent = String(fit.points ?? '–');
    }
    // "all" leaves out the laws the data cannot fit (too few points for their constants), saying why.
    for (const skipped of result.fit_report?.skipped ?? []) {
      const row = table.insertRow();
      row.insertCell().textContent = skipped.model ?? '?';
      const reason = row.insertCell();
      reason.colSpan = 3;
      reason.textContent = `not fitted: ${skipped.reason ?? ''}`;
    }
    const url = await this.m_api.fetch_svg_url(job_id, 'fit.svg');
    if (this.m_plot_url) URL.revokeObjectURL(this.m_plot_url);
    this.m_plot_url = url;
    elements.plot.src = this.m_plot_url;
    elements.result.hidden = false;
  }
}
