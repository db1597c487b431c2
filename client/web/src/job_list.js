// The job list: the caller's jobs (GET /api/v1/jobs, newest first) with their state and latest
// progress, a Reopen button on each and a Cancel button on queued or running ones.
import { show_error } from './field_errors.js';
import { format_error_mm, format_number, format_timestamp, is_active_state, kind_label, state_class, state_label } from './format.js';

export class JobList {
  /**
   * @param {import('./api_client.js').ApiClient} api
   * @param {object} elements  rows (tbody), error, refresh (button)
   * @param {object} actions  on_reopen(job), on_cancel(job) (both may return promises)
   */
  constructor(api, elements, actions) {
    this.m_api = api;
    this.m_elements = elements;
    this.m_actions = actions;
    this.m_current_id = '';
    this.m_jobs = [];
    elements.refresh.addEventListener('click', () => this.refresh());
  }

  /** Highlights the job shown in the job panel. */
  set current_id(job_id) {
    this.m_current_id = job_id;
    this.render();
  }

  /** Reloads the list from the server. */
  async refresh() {
    try {
      const response = await this.m_api.list_jobs(50);
      this.m_jobs = response.jobs ?? [];
      show_error(this.m_elements.error, '');
    } catch (error) {
      show_error(this.m_elements.error, `The job list could not be loaded: ${error.message}`);
      return;
    }
    this.render();
  }

  render() {
    const rows = this.m_elements.rows;
    rows.replaceChildren();
    if (this.m_jobs.length === 0) {
      const row = rows.insertRow();
      const cell = row.insertCell();
      cell.colSpan = 6;
      cell.className = 'hint';
      cell.textContent = 'No jobs yet.';
      return;
    }
    for (const job of this.m_jobs) {
      const row = rows.insertRow();
      row.dataset.jobId = job.id;
      if (job.id === this.m_current_id) row.classList.add('current');

      const badge = document.createElement('span');
      badge.className = `badge ${state_class(job.state)}`;
      badge.textContent = state_label(job.state);
      if (job.state === 'JOB_STATE_QUEUED' && job.queue_position !== undefined)
        badge.title = `${job.queue_position} job(s) ahead`;
      row.insertCell().appendChild(badge);
      row.insertCell().textContent = kind_label(job.kind);
      const what = row.insertCell();
      what.className = 'summary';
      what.textContent = job.summary || job.id;
      if (job.error) {
        const reason = document.createElement('div');
        reason.className = 'error-inline';
        reason.textContent = job.error;
        what.appendChild(reason);
      }
      row.insertCell().textContent = format_timestamp(job.created_ms);
      row.insertCell().textContent = progress_text(job);

      const actions = row.insertCell();
      actions.className = 'row-actions';
      const reopen = document.createElement('button');
      reopen.type = 'button';
      reopen.className = 'button secondary small';
      reopen.textContent = 'Reopen';
      reopen.addEventListener('click', () => this.m_actions.on_reopen(job));
      actions.appendChild(reopen);
      if (is_active_state(job.state)) {
        const cancel = document.createElement('button');
        cancel.type = 'button';
        cancel.className = 'button danger small';
        cancel.textContent = 'Cancel';
        cancel.addEventListener('click', async () => {
          cancel.disabled = true;
          try {
            await this.m_actions.on_cancel(job);
          } catch (error) {
            show_error(this.m_elements.error, `Job ${job.id} could not be cancelled: ${error.message}`);
          }
          await this.refresh();
        });
        actions.appendChild(cancel);
      }
    }
  }
}

/** "it 42, 12.3 s, avg 0.41 mm" from a job's last progress report. */
function progress_text(job) {
  const progress = job.last_progress;
  if (!progress || !(progress.iteration > 0 || progress.elapsed_s > 0)) return '–';
  const parts = [`it ${progress.iteration}`, `${format_number(progress.elapsed_s, 3)} s`];
  if (progress.avg_error_mm >= 0) parts.push(`avg ${format_error_mm(progress.avg_error_mm)} mm`);
  return parts.join(', ');
}
