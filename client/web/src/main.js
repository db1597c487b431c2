// The page: wires the panels together. Step 1 target, step 2 material (or a fit), step 3 settings and
// start; the job panel follows the job live; the job list reopens and cancels jobs.
import { ApiClient } from './api_client.js';
import { base64_from_bytes } from './api_client.js';
import { DesignForm } from './design_form.js';
import { ErrorPlot } from './error_plot.js';
import { curve_spec_for_design } from './curve_request.js';
import { clear_errors, show_error, show_field_errors } from './field_errors.js';
import { FitPanel } from './fit_panel.js';
import { JobList } from './job_list.js';
import { JobPanel } from './job_panel.js';
import { MaterialPanel } from './material_panel.js';
import { load_mesh } from './mesh_loader.js';
import { MeshViewer } from './mesh_viewer.js';
import { recall_target, remember_target } from './target_cache.js';
import { bbox_diagonal, TargetPanel } from './target_panel.js';
import { TokenStore } from './token_store.js';

const $ = (id) => document.getElementById(id);
/** How often the job list refreshes itself while the page is visible (ms). */
const JOB_LIST_REFRESH_MS = 10000;

const token_store = new TokenStore(window.localStorage);
const api = new ApiClient(() => token_store.token, (message) => show_unauthenticated(message));

// ----- token and server status -------------------------------------------------------------------

const token_input = $('token-input');
token_input.value = token_store.token;
token_input.addEventListener('change', () => {
  token_store.token = token_input.value;
  show_error($('token-error'), '');
  reload_everything();
});

function show_unauthenticated(message) {
  show_error($('token-error'), `The server needs a valid API token: ${message}`);
}

async function check_server() {
  const status = $('server-status');
  try {
    await api.health();
    status.textContent = 'server connected';
    status.className = 'server-status ok';
  } catch (error) {
    status.textContent = 'server unreachable';
    status.title = error.message;
    status.className = 'server-status down';
  }
}

// ----- viewer, plot, job panel, list -------------------------------------------------------------

let viewer = null;
try {
  viewer = new MeshViewer($('viewer'));
} catch (error) {
  $('viewer-message').textContent = `This browser cannot draw 3D shapes (WebGL is off or missing): ${error.message}`;
}
if (viewer) {
  // For people and for the browser test: the canvas the viewer draws into.
  viewer.canvas.id = 'viewer-canvas';
  for (const layer of ['target', 'rest', 'inflated']) {
    const box = $(`show-${layer}`);
    box.addEventListener('change', () => viewer.set_visible(layer, box.checked));
  }
}

const plot = new ErrorPlot($('error-plot'));
const material_panel = new MaterialPanel(api, {
  select: $('material-select'), info: $('material-info'), error: $('material-error'),
});

const fit_panel = new FitPanel(api, {
  details: $('fit-details'), csv: $('fit-csv'), csv_error: $('fit-csv-error'), test: $('fit-test'),
  bulge_fields: $('fit-bulge-fields'), radius: $('fit-radius'), thickness: $('fit-thickness'),
  model: $('fit-model'), name: $('fit-name'), name_error: $('fit-name-error'), start: $('fit-start'),
  status: $('fit-status'), error: $('fit-error'), result: $('fit-result'), plot: $('fit-plot'),
  constants: $('fit-constants'),
}, (name) => {
  material_panel.refresh(name);
  job_list.refresh();
});

const job_panel = new JobPanel(api, viewer, plot, {
  panel: $('job-panel'), job_id: $('job-id'), state: $('job-state'),
  readouts: {
    iteration: $('readout-iteration'), elapsed: $('readout-elapsed'), avg_error: $('readout-avg-error'),
    max_error: $('readout-max-error'), pressure: $('readout-pressure'), vertices: $('readout-vertices'),
  },
  summary: $('result-summary'), error: $('job-error'), downloads: document.querySelector('.downloads'),
  download_error: $('download-error'), cancel_button: $('cancel-button'), viewer_message: $('viewer-message'),
  legend: { min: $('legend-min'), max: $('legend-max'), bar: $('legend-bar'), caption: $('legend-caption') },
  curve_figure: $('curve-figure'), curve_plot: $('curve-plot'), curve_button: $('curve-button'),
  curve_error: $('curve-error'),
}, {
  on_change: () => job_list.refresh(),
  on_fit_job: (job_id) => fit_panel.show_result(job_id).catch((error) => show_error($('fit-error'), error.message)),
  on_curve: start_curve,
});

const job_list = new JobList(api, { rows: $('job-rows'), error: $('jobs-error'), refresh: $('jobs-refresh') }, {
  on_reopen: reopen_job,
  on_cancel: async (job) => {
    await api.cancel_job(job.id);
  },
});

// ----- step 1: target ----------------------------------------------------------------------------

const design_form = new DesignForm($('settings-section'));

/** file units -> mm as the server will scale them: bbox diagonal to the asked size (0 keeps). */
function scale_for(mesh, size_mm) {
  if (!mesh || !(size_mm > 0)) return 1;
  const diagonal = bbox_diagonal(mesh);
  return diagonal > 0 ? size_mm / diagonal : 1;
}

function target_context(target) {
  return { name: target.name, mesh: target.mesh, scale: scale_for(target.mesh, design_form.size_mm) };
}

const target_panel = new TargetPanel({
  drop_zone: $('drop-zone'), file_input: $('file-input'), sample_select: $('sample-select'),
  info: $('target-info'), error: $('target-error'),
}, (target) => {
  // A new target replaces what the viewer shows; a job being followed keeps running on the server.
  job_panel.detach();
  job_list.current_id = '';
  show_error($('start-error'), '');
  job_panel.set_target(target.mesh ? target_context(target) : null, true,
    `${target.name} cannot be drawn: see the message under the upload box.`);
});

$('size-input').addEventListener('change', () => {
  const target = target_panel.target;
  if (target && target.mesh && !job_panel.job_id) job_panel.set_target(target_context(target));
});

// ----- step 3: start ------------------------------------------------------------------------------

async function start_design() {
  const start_button = $('start-button');
  clear_errors($('settings-section'));
  show_error($('material-error'), '');
  const target = target_panel.target;
  if (!target) {
    target_panel.show_error('Choose a target shape first: drop a mesh file here or pick a sample.');
    return;
  }
  if (!target.format) return;  // the drop zone already says which formats work
  const design = design_form.read();
  if (!design) return;
  const material = material_panel.selected_name;
  if (!material) {
    material_panel.show_error('Choose a material first.');
    return;
  }
  design.target_mesh = { data: base64_from_bytes(target.bytes), format: target.format };
  design.material = { name: material };

  start_button.disabled = true;
  start_button.textContent = 'Submitting…';
  try {
    const job = await api.submit_job({ design });
    target_panel.show_error('');
    const context = target_context(target);
    job_panel.follow_new(job, context);
    job_list.current_id = job.id;
    job_list.refresh();
    remember_target(job.id, { name: target.name, bytes: target.bytes, size_mm: design.size_mm });
  } catch (error) {
    show_design_error(error);
  } finally {
    start_button.disabled = false;
    start_button.textContent = 'Start design';
  }
}

/** A refused submission: each bad field's message goes under its input, found by the field's path. */
function show_design_error(error) {
  if (error.code === 'UNAUTHENTICATED' || error.code === 'PERMISSION_DENIED') {
    show_error($('start-error'), `Not allowed: ${error.message}`);
    return;
  }
  const fields = error.fields ?? [];
  const unplaced = show_field_errors(document, fields);
  if (unplaced.length > 0 || fields.length === 0) {
    const message = unplaced.length > 0 ? unplaced.map((violation) => violation.description).join(' ') : error.message;
    show_error($('start-error'), `The design was not started: ${message}`);
  }
}

$('start-button').addEventListener('click', start_design);

// ----- the designed balloon's pressure-volume curve ---------------------------------------------------

/** Submits the curve of a completed design (its JobResult) and follows it in the job panel. */
async function start_curve(design_result) {
  const { curve_button: button, curve_error: error_line } = job_panel.elements;
  show_error(error_line, '');
  let spec;
  try {
    spec = curve_spec_for_design(design_result);
  } catch (error) {
    show_error(error_line, `No curve: ${error.message}`);
    return;
  }
  button.disabled = true;
  try {
    const job = await api.submit_job(spec);
    // The curve's shapes are the balloon's own inflation, not a match to the target: no target overlay.
    job_panel.follow_new(job, null);
    job_list.current_id = job.id;
    job_list.refresh();
  } catch (error) {
    show_error(error_line, `The curve was not started: ${error.message}`);
  } finally {
    button.disabled = false;
  }
}

// ----- job list actions -----------------------------------------------------------------------------

async function reopen_job(job) {
  job_list.current_id = job.id;
  let target = null;
  const stored = await recall_target(job.id);
  if (stored) {
    try {
      const mesh = await load_mesh(stored.name, stored.bytes);
      target = { name: stored.name, mesh, scale: scale_for(mesh, stored.size_mm) };
    } catch {
      target = null;
    }
  }
  try {
    const fresh = await api.get_job(job.id);
    await job_panel.reopen(fresh, target);
  } catch (error) {
    show_error($('jobs-error'), `Job ${job.id} could not be reopened: ${error.message}`);
  }
}

// ----- start-up -------------------------------------------------------------------------------------

async function reload_everything() {
  await check_server();
  await Promise.all([material_panel.refresh(), job_list.refresh()]);
}

target_panel.load_samples();
reload_everything();
setInterval(() => {
  if (document.visibilityState === 'visible') job_list.refresh();
}, JOB_LIST_REFRESH_MS);
