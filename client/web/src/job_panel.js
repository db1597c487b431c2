// The job panel: follows one job at a time. While it runs, its Server-Sent Events update the readouts,
// the error plot and the live inflated shape (coloured by distance to the target); when it completes,
// the result's rest and inflated meshes become overlays and the downloads are enabled.
import { bytes_from_base64 } from './api_client.js';
import { save_blob } from './blob_download.js';
import { colors_for_distances, nice_upper_bound, ramp_css_gradient } from './color_map.js';
import { curve_summary_lines } from './curve_summary.js';
import { show_error } from './field_errors.js';
import { format_error_mm, format_number, is_active_state, kind_label, state_label } from './format.js';
import { parse_obj } from './obj_parser.js';
import { pressure_fall_line } from './pressure_fall_line.js';
import { SurfaceDistance } from './surface_distance.js';

/**
 * The target a job's shapes are compared with.
 * @typedef {object} TargetContext
 * @property {string} name  file name
 * @property {{positions: Float32Array, indices: Uint32Array}|null} mesh  as read (file units); null when unreadable
 * @property {number} scale  file units -> the job's mm (the server scales about the origin)
 */

const FILES_BY_KIND = {
  JOB_KIND_DESIGN: ['rest.obj', 'inflated.obj', 'mold.stl', 'report.json', 'convergence.csv'],
  JOB_KIND_SIMULATE: ['rest.obj', 'inflated.obj', 'report.json'],
  JOB_KIND_CURVE: ['rest.obj', 'inflated.obj', 'report.json', 'curve.csv', 'curve.svg'],
};

export class JobPanel {
  /**
   * @param {import('./api_client.js').ApiClient} api
   * @param {import('./mesh_viewer.js').MeshViewer|null} viewer  null when the browser has no WebGL
   * @param {import('./error_plot.js').ErrorPlot} plot
   * @param {object} elements  panel, job_id, state, readouts {iteration, elapsed, avg_error, max_error,
   *   pressure, vertices}, summary, error, downloads (container), download_error, cancel_button,
   *   legend {min, max, bar, caption}, viewer_message, curve_figure, curve_plot (an img), curve_button,
   *   curve_error
   * @param {object} hooks  on_change(job_id, state): the list should refresh; on_fit_job(job_id): show a
   *   completed fit in the fit panel; on_curve(result): start the curve of the design whose JobResult it is
   */
  constructor(api, viewer, plot, elements, hooks) {
    this.m_api = api;
    this.m_viewer = viewer;
    this.m_plot = plot;
    this.m_elements = elements;
    this.m_hooks = hooks;
    this.m_job_id = '';
    this.m_job_kind = '';
    this.m_state = '';
    this.m_abort = null;
    this.m_target = null;
    this.m_distance = null;
    this.m_triangles = null;
    this.m_pending_positions = null;
    this.m_frame_scheduled = false;
    this.m_event_count = 0;
    this.m_mesh_frames = 0;
    this.m_needs_new_mesh = true;
    this.m_design_result = null;
    this.m_curve_url = '';
    elements.legend.bar.style.background = ramp_css_gradient();
    elements.curve_button.addEventListener('click', () => {
      if (this.m_design_result) this.m_hooks.on_curve(this.m_design_result);
    });
    for (const button of elements.downloads.querySelectorAll('button[data-file]'))
      button.addEventListener('click', () => this.download(button.dataset.file, button));
    elements.cancel_button.addEventListener('click', () => this.cancel());
  }

  /** The job shown ('' for none). */
  get job_id() {
    return this.m_job_id;
  }

  // ----- what is shown --------------------------------------------------------------------------

  /** Stops following the current job (it keeps running on the server) and clears the panel. */
  detach() {
    if (this.m_abort) this.m_abort.abort();
    this.m_abort = null;
    this.m_job_id = '';
    this.m_job_kind = '';
    this.m_state = '';
    this.m_triangles = null;
    this.m_needs_new_mesh = true;
    this.m_pending_positions = null;
    this.m_event_count = 0;
    this.m_mesh_frames = 0;
    this.m_plot.reset();
    const { elements } = this;
    elements.job_id.textContent = '';
    elements.state.textContent = 'No job yet.';
    elements.state.className = 'job-state';
    for (const readout of Object.values(elements.readouts)) readout.textContent = '–';
    elements.summary.hidden = true;
    elements.summary.replaceChildren();
    show_error(elements.error, '');
    show_error(elements.download_error, '');
    this.set_downloads([]);
    elements.cancel_button.disabled = true;
    this.m_design_result = null;
    elements.curve_button.hidden = true;
    show_error(elements.curve_error, '');
    this.clear_curve_plot();
    this.update_dataset();
    if (this.m_viewer) {
      this.m_viewer.clear('rest');
      this.m_viewer.clear('inflated');
    }
  }

  get elements() {
    return this.m_elements;
  }

  /**
   * Shows a target (the preview before a job, or a job's target): the target overlay at the job's scale.
   * @param {TargetContext|null} target
   * @param {boolean} [frame]  point the camera at it
   */
  set_target(target, frame = true, empty_message = '') {
    this.m_target = target;
    this.m_distance = null;
    if (!this.m_viewer) return;
    const message = this.m_elements.viewer_message;
    if (target && target.mesh) {
      this.m_viewer.set_mesh('target', target.mesh.positions, target.mesh.indices, target.scale);
      message.hidden = true;
      if (frame) this.m_viewer.frame_all();
    } else {
      this.m_viewer.clear('target');
      if (empty_message) {
        message.textContent = empty_message;
        message.hidden = false;
      }
    }
    this.update_legend(null);
  }

  /** The point-to-surface distance of the current target, built on first use. */
  distance_to_target() {
    if (!this.m_target || !this.m_target.mesh) return null;
    if (!this.m_distance)
      this.m_distance = new SurfaceDistance(this.m_target.mesh.positions, this.m_target.mesh.indices, this.m_target.scale);
    return this.m_distance;
  }

  update_legend(upper_mm) {
    const { legend } = this.m_elements;
    legend.min.textContent = '0 mm';
    legend.max.textContent = upper_mm === null ? '– mm' : `${format_number(upper_mm, 3)} mm`;
    if (this.m_target && this.m_target.mesh) {
      legend.caption.textContent = 'Colour of the inflated shape: distance from each of its vertices to the nearest ' +
        `point of the target surface (mm; exact point-to-triangle distance, computed in this browser).`;
    } else if (this.m_job_id && this.m_job_kind !== 'JOB_KIND_FIT_MATERIAL') {
      legend.caption.textContent = 'No target to compare with: this browser did not submit the job, so the ' +
        'inflated shape is drawn without error colours.';
    } else {
      legend.caption.textContent = 'Colour of the inflated shape: distance from each of its vertices to the nearest ' +
        'point of the target surface (mm), once a design runs.';
    }
  }

  update_dataset() {
    const panel = this.m_elements.panel;
    panel.dataset.jobId = this.m_job_id;
    panel.dataset.state = this.m_state;
    panel.dataset.events = String(this.m_event_count);
    panel.dataset.meshFrames = String(this.m_mesh_frames);
  }

  set_state(state, message = '') {
    this.m_state = state;
    const label = state_label(state);
    this.m_elements.state.textContent = message ? `${label}: ${message}` : label;
    this.m_elements.state.className = `job-state ${label.toLowerCase()}`;
    this.m_elements.cancel_button.disabled = !is_active_state(state);
    this.update_dataset();
  }

  set_downloads(files) {
    for (const button of this.m_elements.downloads.querySelectorAll('button[data-file]'))
      button.disabled = !files.includes(button.dataset.file);
  }

  // ----- following a job ------------------------------------------------------------------------

  /**
   * Follows a job just submitted.
   * @param {object} job  the stored Job (QUEUED)
   * @param {TargetContext} target
   */
  follow_new(job, target) {
    this.detach();
    this.set_target(target);
    this.m_job_id = job.id;
    this.m_job_kind = job.kind;
    this.m_elements.job_id.textContent = job.id;
    this.set_state(job.state, 'waiting for a worker');
    this.watch(job.id);
  }

  /**
   * Reopens a job from the list: its target (when this browser has it), live view or result.
   * @param {object} job  a Job from the list
   * @param {TargetContext|null} target
   */
  async reopen(job, target) {
    this.detach();
    this.m_job_id = job.id;
    this.m_job_kind = job.kind;
    this.m_elements.job_id.textContent = job.id;
    this.set_target(target);
    this.set_state(job.state, job.error);
    if (job.last_progress) this.show_readouts(job.last_progress);
    if (job.kind === 'JOB_KIND_FIT_MATERIAL' && this.m_viewer) {
      this.m_elements.viewer_message.textContent = 'A material fit has no shape: its plot and constants are under “Material”.';
      this.m_elements.viewer_message.hidden = false;
    }
    if (is_active_state(job.state)) {
      this.watch(job.id);
      return;
    }
    await this.show_finished(job);
  }

  async cancel() {
    if (!this.m_job_id) return;
    this.m_elements.cancel_button.disabled = true;
    try {
      const job = await this.m_api.cancel_job(this.m_job_id);
      this.set_state(job.state, job.error);
    } catch (error) {
      show_error(this.m_elements.error, `The job could not be cancelled: ${error.message}`);
      this.m_elements.cancel_button.disabled = false;
    }
  }

  async watch(job_id) {
    const abort = new AbortController();
    this.m_abort = abort;
    let end;
    try {
      end = await this.m_api.watch_job(job_id, (event) => this.take_event(job_id, event), abort.signal);
    } catch (error) {
      if (abort.signal.aborted) return;  // the user moved on to another job
      this.report_error(`Watching the job stopped: ${error.message}`);
      return;
    }
    if (abort.signal.aborted || this.m_job_id !== job_id) return;
    this.m_abort = null;
    if (end.code !== 'OK') show_error(this.m_elements.error, `Watching the job stopped: ${end.message || end.code}`);
    try {
      const job = await this.m_api.get_job(job_id);
      if (this.m_job_id !== job_id) return;
      this.set_state(job.state, job.error);
      this.m_hooks.on_change(job_id, job.state);
      if (!is_active_state(job.state)) await this.show_finished(job);
    } catch (error) {
      this.report_error(`The job's final state could not be read: ${error.message}`);
    }
  }

  report_error(message) {
    show_error(this.m_elements.error, message);
  }

  /** One JobEvent of the watched job. */
  take_event(job_id, event) {
    if (job_id !== this.m_job_id) return;
    ++this.m_event_count;
    const previous_state = this.m_state;
    if (event.state && event.state !== 'JOB_STATE_UNSPECIFIED') {
      const progress = event.progress;
      const detail = progress && progress.phase ? `${progress.phase}, iteration ${progress.iteration}` : event.message;
      this.set_state(event.state, detail || '');
    }
    if (event.state !== previous_state) this.m_hooks.on_change(job_id, event.state);
    if (event.progress) this.take_progress(event.progress);
    if (event.mesh) this.take_mesh(event.mesh);
    this.update_dataset();
  }

  take_progress(progress) {
    this.show_readouts(progress);
    // After the design, the check inflates its rest shape from rest and the tolerance phase re-inflates
    // perturbed copies; neither has the design's errors.
    if (progress.phase !== 'tolerance' && progress.phase !== 'check') this.m_plot.add_point(progress.elapsed_s, progress.avg_error_mm);
  }

  /** The readouts for one Progress message. */
  show_readouts(progress) {
    const { readouts } = this.m_elements;
    readouts.iteration.textContent = String(progress.iteration ?? '–');
    readouts.elapsed.textContent = format_number(progress.elapsed_s, 3);
    readouts.avg_error.textContent = format_error_mm(progress.avg_error_mm);
    readouts.max_error.textContent = format_error_mm(progress.max_error_mm);
    readouts.pressure.textContent = progress.pressure_kpa > 0 ? format_number(progress.pressure_kpa, 4) : '–';
  }

  take_mesh(mesh) {
    if (mesh.triangles && mesh.triangles.length > 0) {
      this.m_triangles = Uint32Array.from(mesh.triangles);
      this.m_needs_new_mesh = true;
    }
    if (!this.m_triangles || !mesh.positions_mm || mesh.positions_mm.length === 0) return;
    ++this.m_mesh_frames;
    this.m_elements.readouts.vertices.textContent = String(mesh.vertex_count ?? mesh.positions_mm.length / 3);
    // Only the newest shape is drawn; frames arriving faster than the screen refreshes are skipped.
    this.m_pending_positions = Float32Array.from(mesh.positions_mm);
    if (this.m_frame_scheduled) return;
    this.m_frame_scheduled = true;
    requestAnimationFrame(() => {
      this.m_frame_scheduled = false;
      const positions = this.m_pending_positions;
      this.m_pending_positions = null;
      if (positions && this.m_state !== 'JOB_STATE_COMPLETED') this.draw_inflated(positions, this.m_triangles);
    });
  }

  /** Draws an inflated shape coloured by its distance to the target. */
  draw_inflated(positions, triangles) {
    if (!this.m_viewer) return;
    const fresh = this.m_needs_new_mesh || !this.m_viewer.update_positions('inflated', positions);
    if (fresh) {
      const had_target = this.m_viewer.has('target');
      this.m_viewer.set_mesh('inflated', positions, triangles);
      this.m_needs_new_mesh = false;
      this.m_elements.viewer_message.hidden = true;
      if (!had_target) this.m_viewer.frame_all();
    }
    const distance = this.distance_to_target();
    if (!distance) return;
    const distances = distance.distances(positions);
    let largest = 0;
    for (const value of distances) if (value > largest) largest = value;
    const upper = nice_upper_bound(largest);
    this.m_viewer.set_colors('inflated', colors_for_distances(distances, upper));
    this.update_legend(upper);
  }

  // ----- finished jobs --------------------------------------------------------------------------

  async show_finished(job) {
    if (job.state === 'JOB_STATE_COMPLETED') {
      if (job.kind === 'JOB_KIND_FIT_MATERIAL') {
        this.m_elements.state.textContent = 'Completed: the material fit is shown under “Material”.';
        this.m_hooks.on_fit_job(job.id);
        return;
      }
      await this.load_result(job);
    } else if (job.state === 'JOB_STATE_FAILED') {
      show_error(this.m_elements.error, `The job failed: ${job.error || 'no reason given'}`);
    } else if (job.state === 'JOB_STATE_CANCELLED') {
      show_error(this.m_elements.error, `The job was cancelled${job.error ? `: ${job.error}` : '.'}`);
    }
  }

  async load_result(job) {
    let result;
    try {
      result = await this.m_api.get_result(job.id);
    } catch (error) {
      this.report_error(`The result could not be loaded: ${error.message}`);
      return;
    }
    if (this.m_job_id !== job.id) return;
    // The typed report of the job's kind (the gateway's JSON of JobResult); an error never computed is absent.
    const report = result.design_report ?? result.simulate_report ?? result.curve_report ?? {};
    // The report knows the exact scale the server applied to the target.
    const scale = report.preparation?.scale_factor;
    if (this.m_target && this.m_target.mesh && Number.isFinite(scale) && scale > 0 && scale !== this.m_target.scale)
      this.set_target({ ...this.m_target, scale }, false);

    if (this.m_viewer) {
      const decoder = new TextDecoder();
      try {
        const rest = parse_obj(decoder.decode(bytes_from_base64(result.rest_mesh?.data ?? '')));
        const inflated = parse_obj(decoder.decode(bytes_from_base64(result.inflated_mesh?.data ?? '')));
        const had_shapes = this.m_viewer.has('target') || this.m_viewer.has('inflated');
        this.m_viewer.set_mesh('rest', rest.positions, rest.indices);
        this.m_needs_new_mesh = true;
        this.draw_inflated(inflated.positions, inflated.indices);
        this.m_elements.viewer_message.hidden = true;
        if (!had_shapes) this.m_viewer.frame_all();
        this.m_elements.readouts.vertices.textContent = String(rest.positions.length / 3);
      } catch (error) {
        show_error(this.m_elements.error, `The result's meshes could not be read: ${error.message}`);
      }
    }
    const convergence = report.convergence;
    if (convergence && Array.isArray(convergence.time_s))
      this.m_plot.set_points(convergence.time_s, convergence.avg_error_mm ?? []);
    this.show_summary(job, report);
    this.set_downloads(FILES_BY_KIND[job.kind] ?? []);
    // A designed balloon (one whose start inflated) can have its pressure-volume curve computed.
    if (job.kind === 'JOB_KIND_DESIGN' && report.volume_ratio != null) {
      this.m_design_result = result;
      this.m_elements.curve_button.hidden = false;
    }
    if (result.curve_report) await this.show_curve_plot(job);
  }

  /** A curve job's plot (curve.svg, pressure maxima and minima marked) under the summary. */
  async show_curve_plot(job) {
    const { curve_figure, curve_plot } = this.m_elements;
    try {
      const url = await this.m_api.fetch_svg_url(job.id, 'curve.svg');
      if (this.m_job_id !== job.id) {
        URL.revokeObjectURL(url);
        return;
      }
      this.clear_curve_plot();
      this.m_curve_url = url;
      curve_plot.src = url;
      curve_figure.hidden = false;
    } catch (error) {
      show_error(this.m_elements.error, `The curve's plot could not be loaded: ${error.message}`);
    }
  }

  clear_curve_plot() {
    const { curve_figure, curve_plot } = this.m_elements;
    if (this.m_curve_url) URL.revokeObjectURL(this.m_curve_url);
    this.m_curve_url = '';
    curve_plot.removeAttribute('src');
    curve_figure.hidden = true;
  }

  show_summary(job, report) {
    const { readouts, summary } = this.m_elements;
    if (report.avg_error_mm != null) readouts.avg_error.textContent = format_error_mm(report.avg_error_mm);
    if (report.max_error_mm != null) readouts.max_error.textContent = format_error_mm(report.max_error_mm);
    if (report.pressure_kpa != null) readouts.pressure.textContent = format_number(report.pressure_kpa, 4);
    if (report.time_s !== undefined) readouts.elapsed.textContent = format_number(report.time_s, 3);
    if (report.iterations !== undefined) readouts.iteration.textContent = String(report.iterations);

    const lines = [];
    const converged = report.converged ?? job.converged;
    // The stop word and the sentence only where they add to "converged".
    const stop = report.stop_reason && report.stop_reason !== 'converged' ? report.stop_reason : '';
    const message = report.message && report.message !== 'converged' && report.message !== stop ? report.message : '';
    lines.push(`${kind_label(job.kind)} ${converged ? 'converged' : 'stopped before converging'}` +
      (stop ? ` [${stop.replace('_', ' ')}]` : '') + (message ? ` (${message})` : ''));
    if (job.kind === 'JOB_KIND_DESIGN' && report.avg_error_mm == null)
      lines.push('No design error: the start shape was never inflated, so there is nothing to compare.');
    if (report.avg_error_mm != null)
      lines.push(`Inflated shape vs target: average ${format_error_mm(report.avg_error_mm)} mm, largest ` +
        `${format_error_mm(report.max_error_mm)} mm, on a ${format_number(report.bbox_diag_mm, 4)} mm bounding-box diagonal ` +
        `(${format_number(100 * report.avg_error_rel, 3)} % / ${format_number(100 * report.max_error_rel, 3)} %).`);
    if (report.baseline_avg_error_mm != null)
      lines.push(`Just shrinking the target would give an average error of ${format_error_mm(report.baseline_avg_error_mm)} mm.`);
    if (report.pressure_kpa != null)
      lines.push(`Inflate to ${format_number(report.pressure_kpa, 4)} kPa; volume ratio ${format_number(report.volume_ratio, 4)}; ` +
        `${report.vertices ?? '?'} vertices; ${report.material_name || report.material || ''}, ${format_number(report.thickness_mm, 3)} mm thick.`);
    const from_rest = report.from_rest;
    if (from_rest && from_rest.avg_error_mm != null)
      lines.push(`Inflated from rest, as a maker inflates it: ${from_rest.another_shape ? 'ANOTHER SHAPE than the design\'s' : 'the design\'s shape'}, ` +
        `average ${format_error_mm(from_rest.avg_error_mm)} mm at ${format_number(from_rest.pressure_kpa, 4)} kPa ` +
        `(${format_error_mm(from_rest.deviation_mm)} mm from the design's shape on average)` +
        (from_rest.unstable_modes > 0 ? `; there it is a saddle under volume control (${from_rest.unstable_modes} unstable ` +
          'directions: wrinkling or symmetry breaking), and the real balloon may take another shape.' : '.'));
    else if (from_rest && from_rest.message) lines.push(from_rest.message);
    const pressure_fall = pressure_fall_line(report.pressure_fall);
    if (pressure_fall) lines.push(pressure_fall);
    if (report.mold_problem) lines.push(`No mold: ${report.mold_problem}`);
    if (job.kind === 'JOB_KIND_CURVE') lines.push(...curve_summary_lines(report));
    summary.replaceChildren(...lines.map((line) => {
      const paragraph = document.createElement('p');
      paragraph.textContent = line;
      return paragraph;
    }));
    summary.hidden = false;
  }

  async download(file_name, button) {
    if (!this.m_job_id) return;
    show_error(this.m_elements.download_error, '');
    button.disabled = true;
    try {
      const blob = await this.m_api.fetch_file(this.m_job_id, file_name);
      save_blob(blob, file_name);
    } catch (error) {
      show_error(this.m_elements.download_error, `${file_name} could not be downloaded: ${error.message}`);
    } finally {
      button.disabled = false;
    }
  }
}
