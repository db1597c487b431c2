// Browser test of the web frontend (issue 6): a real balloon-server with its HTTP gateway and the built
// page, driven in headless Chromium (Debian's /usr/bin/chromium) through playwright-core.
//
//   node tests/web/browser_test.mjs --server BUILD/server/balloon-server --web-root BUILD/client/web/dist
//                                   [--artifacts DIR] [--chromium /usr/bin/chromium]
// (or the environment variables BALLOON_SERVER_BIN, BALLOON_WEB_ROOT, BALLOON_TEST_ARTIFACTS, CHROMIUM_PATH)
//
// It loads the page, designs a balloon for the sample cube (about 400 vertices, 10 s budget), sees
// progress events arrive and the job complete, checks that the viewer drew the shape, downloads
// rest.obj and parses it, starts the designed balloon's pressure-volume curve and sees its plot, checks
// that a refused thickness is shown under the thickness input and a bad
// upload (dropped on the drop zone) next to the upload control: the server's errors are placed by the
// field path they name (the API's error.fields), whatever their words.
// Every request leaving loopback is aborted and recorded, and the test fails if there was any.
// Screenshots of each step go to the artifacts folder. Exit status 0 only if every check passed.
import { spawn } from 'node:child_process';
import { createWriteStream, existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { chromium } from 'playwright-core';

/** Whole test budget (s): well under the 3 minutes the CI step may take. */
const TOTAL_BUDGET_S = 170;
/** How long the design job may take from submission to completion (s). */
const JOB_TIMEOUT_S = 120;
/** The viewer's background (mesh_viewer.js VIEWER_BACKGROUND = 0xf3f5f8). */
const BACKGROUND_RGB = [0xf3, 0xf5, 0xf8];

// ----- arguments ------------------------------------------------------------------------------------

function parse_arguments(argv) {
  const options = {
    server: process.env.BALLOON_SERVER_BIN ?? '',
    web_root: process.env.BALLOON_WEB_ROOT ?? '',
    artifacts: process.env.BALLOON_TEST_ARTIFACTS ?? '',
    chromium: process.env.CHROMIUM_PATH ?? '/usr/bin/chromium',
  };
  for (let i = 0; i < argv.length; ++i) {
    const value = argv[i + 1];
    switch (argv[i]) {
      case '--server': options.server = value; ++i; break;
      case '--web-root': options.web_root = value; ++i; break;
      case '--artifacts': options.artifacts = value; ++i; break;
      case '--chromium': options.chromium = value; ++i; break;
      default:
        fail_early(`unknown argument '${argv[i]}'`);
    }
  }
  if (!options.server) fail_early('give --server PATH of balloon-server (or BALLOON_SERVER_BIN)');
  if (!options.web_root) fail_early('give --web-root DIR of the built page (or BALLOON_WEB_ROOT)');
  options.server = resolve(options.server);
  options.web_root = resolve(options.web_root);
  options.artifacts = resolve(options.artifacts || 'test-artifacts/web');
  if (!existsSync(options.server)) fail_early(`balloon-server not found at ${options.server}`);
  if (!existsSync(join(options.web_root, 'index.html')))
    fail_early(`the page is not built: ${options.web_root}/index.html is missing (build the balloon_web target)`);
  if (!existsSync(options.chromium))
    fail_early(`Chromium not found at ${options.chromium} (Debian package 'chromium'; deploy/install-deps.sh installs it)`);
  return options;
}

function fail_early(message) {
  console.error(`browser test: ${message}`);
  process.exit(2);
}

// ----- checks ---------------------------------------------------------------------------------------

const results = [];
const started_at = Date.now();
/** The server process, so every way out (including the budget timer and Ctrl-C) can stop it. */
let running_server = null;

function elapsed_s() {
  return ((Date.now() - started_at) / 1000).toFixed(1);
}

function log(message) {
  console.log(`[browser ${elapsed_s()} s] ${message}`);
}

/** Records one check; a failed one is printed with its reason and the test goes on where it can. */
function check(name, passed, detail = '') {
  results.push({ name, passed, detail });
  console.log(`${passed ? 'PASS' : 'FAIL'} ${name}${detail ? `: ${detail}` : ''}`);
  return passed;
}

/** A step that must work for the following ones to make sense: throws on failure. */
function require_check(name, passed, detail = '') {
  if (!check(name, passed, detail)) throw new Error(`${name} failed${detail ? `: ${detail}` : ''}`);
}

function is_loopback_host(hostname) {
  const host = hostname.replace(/^\[|\]$/g, '');
  return host === 'localhost' || host === '::1' || /^127\.\d+\.\d+\.\d+$/.test(host);
}

// ----- the server -----------------------------------------------------------------------------------

/** Starts balloon-server on free ports; resolves with {process, port} once it prints its http line. */
function start_server(options, work_dir) {
  return new Promise((resolve_start, reject_start) => {
    const args = [
      '--listen', '127.0.0.1:0', '--http', '127.0.0.1:0', '--db', join(work_dir, 'test.db'),
      '--web-root', options.web_root, '--workers', '1',
    ];
    log(`starting ${options.server} ${args.join(' ')}`);
    const server = spawn(options.server, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    const server_log = createWriteStream(join(options.artifacts, 'server.log'));
    let stdout = '';
    let settled = false;
    const timer = setTimeout(() => {
      if (settled) return;
      settled = true;
      reject_start(new Error(`balloon-server printed no 'http on 127.0.0.1:PORT' line within 20 s; stdout so far: ${stdout}`));
    }, 20000);
    server.stdout.on('data', (chunk) => {
      server_log.write(chunk);
      stdout += chunk.toString();
      const match = /http on 127\.0\.0\.1:(\d+)/.exec(stdout);
      if (match && !settled) {
        settled = true;
        clearTimeout(timer);
        resolve_start({ process: server, port: Number(match[1]) });
      }
    });
    server.stderr.on('data', (chunk) => server_log.write(chunk));
    server.on('exit', (code, signal) => {
      if (settled) return;
      settled = true;
      clearTimeout(timer);
      reject_start(new Error(`balloon-server exited early (code ${code}, signal ${signal}); see ${join(options.artifacts, 'server.log')}`));
    });
    server.on('error', (error) => {
      if (settled) return;
      settled = true;
      clearTimeout(timer);
      reject_start(error);
    });
  });
}

/** SIGTERM, then SIGKILL if it has not exited within 5 s. */
async function stop_server(server) {
  if (!server || server.exitCode !== null || server.signalCode !== null) return;
  const exited = new Promise((resolve_exit) => server.once('exit', resolve_exit));
  server.kill('SIGTERM');
  const timeout = new Promise((resolve_timeout) => setTimeout(() => resolve_timeout('timeout'), 5000));
  if ((await Promise.race([exited, timeout])) === 'timeout') {
    server.kill('SIGKILL');
    await exited;
  }
}

// ----- page helpers ---------------------------------------------------------------------------------

/** Counts canvas pixels that differ from the viewer's background (reads the WebGL drawing buffer). */
async function count_drawn_pixels(page) {
  return page.evaluate((background) => {
    const canvas = document.getElementById('viewer-canvas');
    if (!canvas) return { drawn: 0, total: 0, reason: 'no #viewer-canvas' };
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context = copy.getContext('2d');
    context.drawImage(canvas, 0, 0);
    const pixels = context.getImageData(0, 0, copy.width, copy.height).data;
    let drawn = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      const differs = Math.abs(pixels[i] - background[0]) > 12 || Math.abs(pixels[i + 1] - background[1]) > 12 ||
        Math.abs(pixels[i + 2] - background[2]) > 12;
      if (differs) ++drawn;
    }
    return { drawn, total: pixels.length / 4 };
  }, BACKGROUND_RGB);
}

/** Parses OBJ text strictly: counts v and f lines, checks every number is finite and every index exists. */
function parse_obj_strictly(text) {
  let vertices = 0;
  let faces = 0;
  const problems = [];
  const face_indices = [];
  for (const [number, raw] of text.split(/\r?\n/).entries()) {
    const words = raw.trim().split(/\s+/);
    if (words[0] === 'v') {
      ++vertices;
      const coordinates = words.slice(1, 4).map(Number);
      if (coordinates.length !== 3 || !coordinates.every(Number.isFinite)) problems.push(`line ${number + 1}: '${raw}'`);
    } else if (words[0] === 'f') {
      ++faces;
      const indices = words.slice(1).map((word) => Number.parseInt(word.split('/')[0], 10));
      if (indices.length < 3 || !indices.every(Number.isInteger)) problems.push(`line ${number + 1}: '${raw}'`);
      face_indices.push(...indices);
    }
  }
  for (const index of face_indices)
    if (index < 1 || index > vertices) {
      problems.push(`face index ${index} outside 1..${vertices}`);
      break;
    }
  return { vertices, faces, problems };
}

// ----- the test -------------------------------------------------------------------------------------

async function run(options) {
  mkdirSync(options.artifacts, { recursive: true });
  const work_dir = mkdtempSync(join(tmpdir(), 'balloon-browser-test-'));
  let server = null;
  let context = null;
  const outside_requests = [];
  const page_errors = [];
  let shot = 0;
  try {
    const started = await start_server(options, work_dir);
    server = started.process;
    running_server = server;
    const base_url = `http://127.0.0.1:${started.port}/`;
    log(`server http on ${base_url}`);

    context = await chromium.launchPersistentContext(join(work_dir, 'chromium-profile'), {
      executablePath: options.chromium,
      headless: true,
      acceptDownloads: true,
      viewport: { width: 1400, height: 1100 },
      args: [
        '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
        '--disable-component-update', '--disable-sync',
        // Belt and braces: the browser cannot even resolve a name outside loopback.
        '--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE localhost, EXCLUDE 127.0.0.1',
      ],
    });
    // Every request goes through here: loopback continues, anything else is aborted and recorded.
    await context.route('**/*', (route) => {
      const url = new URL(route.request().url());
      if ((url.protocol === 'http:' || url.protocol === 'https:' || url.protocol === 'ws:' || url.protocol === 'wss:') &&
          !is_loopback_host(url.hostname)) {
        outside_requests.push(route.request().url());
        return route.abort('blockedbyclient');
      }
      return route.continue();
    });
    context.on('request', (request) => {
      const url = new URL(request.url());
      if (/^(https?|wss?):$/.test(url.protocol) && !is_loopback_host(url.hostname) && !outside_requests.includes(request.url()))
        outside_requests.push(request.url());
    });

    const page = context.pages()[0] ?? (await context.newPage());
    page.setDefaultTimeout(30000);
    page.on('pageerror', (error) => page_errors.push(error.message));
    page.on('console', (message) => {
      if (message.type() === 'error') console.log(`  page console error: ${message.text()}`);
    });
    const screenshot = async (name) => {
      const file = join(options.artifacts, `${String(++shot).padStart(2, '0')}-${name}.png`);
      await page.screenshot({ path: file, fullPage: true });
      log(`screenshot ${file}`);
    };

    // 1. The page loads, talks to the server and lists the materials.
    await page.goto(base_url);
    await page.waitForFunction(() => document.getElementById('server-status')?.textContent === 'server connected');
    await page.waitForFunction(() => document.querySelectorAll('#material-select option').length > 0);
    const materials = await page.$$eval('#material-select option', (options_) => options_.map((option) => option.value));
    require_check('page loads and lists materials', materials.includes('latex'), `materials: ${materials.join(', ')}`);
    await screenshot('loaded');

    // 2. A sample target, small settings. The cube runs into its 10 s budget (the sphere converges in
    // about a second, too fast to watch), so progress arrives over several seconds.
    await page.waitForFunction(() => document.querySelector('#sample-select option[value="cube_866.off"]'));
    await page.selectOption('#sample-select', 'cube_866.off');
    await page.waitForFunction(() => document.getElementById('target-info').textContent.includes('866 vertices, 1728 triangles'));
    await page.selectOption('#material-select', 'latex');
    await page.fill('#size-input', '100');
    await page.fill('#resolution-input', '400');
    await page.fill('#max-time-input', '10');
    await page.fill('#volume-ratio-input', '8');
    check('sample target is read', true, await page.textContent('#target-info'));
    await screenshot('target-chosen');

    // 3. Start; progress events arrive (events counted, readouts change, the plot gets points).
    // Every value the iteration readout takes is recorded in the page, however fast events come.
    await page.evaluate(() => {
      window.seen_iterations = [];
      const readout = document.getElementById('readout-iteration');
      new MutationObserver(() => {
        const text = readout.textContent;
        if (text !== '–' && window.seen_iterations[window.seen_iterations.length - 1] !== text) window.seen_iterations.push(text);
      }).observe(readout, { childList: true, characterData: true, subtree: true });
    });
    await page.click('#start-button');
    await page.waitForFunction(() => document.getElementById('job-panel').dataset.jobId !== '', null, { timeout: 20000 })
      .catch(() => {});
    const job_id = await page.$eval('#job-panel', (panel) => panel.dataset.jobId);
    const start_error = await page.$$eval('.error:not([hidden])', (elements) => elements.map((element) => element.textContent).join(' | '));
    require_check('design job submitted', Boolean(job_id), job_id || `no job id; errors shown: ${start_error}`);

    await page.waitForFunction(() => {
      const panel = document.getElementById('job-panel');
      const plot_points = Number(document.getElementById('error-plot').dataset.points);
      return Number(panel.dataset.events) >= 5 && plot_points >= 3 && window.seen_iterations.length >= 3 &&
        Number(panel.dataset.meshFrames) >= 2;
    }, null, { timeout: 60000 }).catch(() => {});
    const progress = await page.evaluate(() => ({
      iterations: window.seen_iterations.slice(),
      events: Number(document.getElementById('job-panel').dataset.events),
      mesh_frames: Number(document.getElementById('job-panel').dataset.meshFrames),
      points: Number(document.getElementById('error-plot').dataset.points),
      iteration: document.getElementById('readout-iteration').textContent,
      avg_error: document.getElementById('readout-avg-error').textContent,
      state: document.getElementById('job-state').textContent,
    }));
    check('progress events arrive', progress.events >= 5 && progress.points >= 3 && progress.mesh_frames >= 2 &&
      progress.iterations.length >= 3,
      `${progress.events} events, ${progress.mesh_frames} live meshes, ${progress.points} plot points, ` +
      `iterations shown ${progress.iterations.slice(0, 8).join(', ')}${progress.iterations.length > 8 ? ', ...' : ''}; ` +
      `avg error ${progress.avg_error} mm (${progress.state})`);
    await screenshot('running');

    // 4. The job completes.
    const final_state = await page.waitForFunction(() => {
      const state = document.getElementById('job-panel').dataset.state;
      return state === 'JOB_STATE_COMPLETED' || state === 'JOB_STATE_FAILED' || state === 'JOB_STATE_CANCELLED' ? state : null;
    }, null, { timeout: JOB_TIMEOUT_S * 1000 }).then((handle) => handle.jsonValue()).catch(() => 'timeout');
    const job_error = await page.textContent('#job-error');
    require_check('design job completes', final_state === 'JOB_STATE_COMPLETED', `${final_state} ${job_error}`.trim());
    // The result (meshes, report) loads after the state changes; the download buttons come with it.
    await page.waitForFunction(() => !document.querySelector('button[data-file="rest.obj"]').disabled);
    log(`result: ${(await page.textContent('#result-summary')).trim()}`);
    await page.waitForTimeout(300);  // one animation frame for the result's meshes
    await screenshot('completed');

    // 5. The viewer drew the shape: with only the inflated overlay on, many pixels differ from the background.
    for (const layer of ['target', 'rest']) await page.uncheck(`#show-${layer}`);
    await page.waitForTimeout(200);
    const inflated_only = await count_drawn_pixels(page);
    await screenshot('inflated-only');
    for (const layer of ['target', 'rest']) await page.check(`#show-${layer}`);
    await page.waitForTimeout(200);
    const all_layers = await count_drawn_pixels(page);
    const share = inflated_only.total > 0 ? inflated_only.drawn / inflated_only.total : 0;
    check('viewer drew the shape (non-blank canvas)', inflated_only.drawn > 2000 && share > 0.02 && all_layers.drawn >= inflated_only.drawn * 0.9,
      `inflated only: ${inflated_only.drawn} of ${inflated_only.total} pixels (${(100 * share).toFixed(1)} %); all overlays: ${all_layers.drawn}`);

    // 6. Download rest.obj through the page's button and parse it.
    const [download] = await Promise.all([
      page.waitForEvent('download', { timeout: 30000 }),
      page.click('button[data-file="rest.obj"]'),
    ]);
    const rest_path = join(options.artifacts, 'rest.obj');
    await download.saveAs(rest_path);
    const rest = parse_obj_strictly(readFileSync(rest_path, 'utf8'));
    check('rest.obj downloads and parses', download.suggestedFilename() === 'rest.obj' && rest.vertices > 0 && rest.faces > 0 && rest.problems.length === 0,
      `${download.suggestedFilename()}: ${rest.vertices} vertices, ${rest.faces} faces${rest.problems.length ? `; problems: ${rest.problems.slice(0, 3).join('; ')}` : ''}`);

    // 6b. The designed balloon's pressure-volume curve: started from the page as a curve job, followed in
    // the job panel, its plot (curve.svg) shown with the summary's count of converged equilibria.
    await page.click('#curve-button');
    await page.waitForFunction((design_id) => {
      const id = document.getElementById('job-panel').dataset.jobId;
      return id !== '' && id !== design_id;
    }, job_id, { timeout: 20000 }).catch(() => {});
    const curve_state = await page.waitForFunction(() => {
      const state = document.getElementById('job-panel').dataset.state;
      return state === 'JOB_STATE_COMPLETED' || state === 'JOB_STATE_FAILED' || state === 'JOB_STATE_CANCELLED' ? state : null;
    }, null, { timeout: 60000 }).then((handle) => handle.jsonValue()).catch(() => 'timeout');
    await page.waitForFunction(() => {
      const plot = document.getElementById('curve-plot');
      return !document.getElementById('curve-figure').hidden && plot.complete && plot.naturalWidth > 0;
    }, null, { timeout: 20000 }).catch(() => {});
    const curve = await page.evaluate(() => ({
      job: document.getElementById('job-panel').dataset.jobId,
      shown: !document.getElementById('curve-figure').hidden,
      width: document.getElementById('curve-plot').naturalWidth,
      summary: document.getElementById('result-summary').textContent,
      errors: `${document.getElementById('curve-error').textContent} ${document.getElementById('job-error').textContent}`.trim(),
    }));
    check('curve of the design: a curve job completes and its plot is shown',
      curve.job !== job_id && curve_state === 'JOB_STATE_COMPLETED' && curve.shown && curve.width > 0 &&
        /\d+ of \d+ equilibria converged/.test(curve.summary),
      `job ${curve.job}: ${curve_state}; plot ${curve.shown ? `${curve.width} px wide` : 'not shown'}; ` +
        `${curve.summary.trim().slice(0, 300)} ${curve.errors}`.trim());
    await screenshot('curve');

    // 7. A thickness the server refuses (the page checks only that it is a number): the server's description
    // of the field "design.thickness_mm" appears under the thickness input, and nowhere else.
    const refused_submission = () => page.waitForResponse(
      (response) => response.url().endsWith('/api/v1/jobs') && response.request().method() === 'POST', { timeout: 20000 });
    await page.fill('#thickness-input', '-1');
    const [thickness_response] = await Promise.all([refused_submission(), page.click('#start-button')]);
    const thickness_body = await thickness_response.json().catch(() => ({}));
    const thickness_field = (thickness_body.error?.fields ?? []).find((field) => field.field === 'design.thickness_mm');
    await page.waitForFunction(() => !document.getElementById('thickness-error').hidden, null, { timeout: 10000 }).catch(() => {});
    const thickness_shown = await page.$$eval('.error:not([hidden])', (elements) => elements.map((element) => [element.id, element.textContent]));
    check('refused thickness: its message is shown under the thickness input, found by field path',
      thickness_response.status() === 400 && thickness_field !== undefined && thickness_shown.length === 1 &&
        thickness_shown[0][0] === 'thickness-error' && thickness_shown[0][1] === thickness_field.description,
      `${thickness_response.status()} ${JSON.stringify(thickness_body)}; shown: ${JSON.stringify(thickness_shown)}`);
    await screenshot('refused-thickness');
    await page.fill('#thickness-input', '0.5');

    // 8. A bad upload, dropped on the drop zone as a person would drag it there: the page says so under
    // the upload box, and so does the server when the design starts anyway.
    await page.evaluate(() => {
      const transfer = new DataTransfer();
      transfer.items.add(new File(['this is not a mesh\nhello world 1 2 3\n'], 'bad.obj', { type: 'text/plain' }));
      const zone = document.getElementById('drop-zone');
      for (const type of ['dragenter', 'dragover', 'drop'])
        zone.dispatchEvent(new DragEvent(type, { dataTransfer: transfer, bubbles: true, cancelable: true }));
    });
    await page.waitForFunction(() => {
      const error = document.getElementById('target-error');
      return !error.hidden && error.textContent.includes('bad.obj');
    }, null, { timeout: 10000 }).catch(() => {});
    const local_error = await page.$eval('#target-error', (element) => (element.hidden ? '' : element.textContent));
    check('bad upload: the page explains it under the upload box', local_error.length > 0, local_error);
    await screenshot('bad-upload');
    const [upload_response] = await Promise.all([refused_submission(), page.click('#start-button')]);
    const upload_body = await upload_response.json().catch(() => ({}));
    const upload_field = (upload_body.error?.fields ?? []).find((field) => field.field === 'design.target_mesh');
    await page.waitForFunction((expected) => document.getElementById('target-error').textContent === expected,
      upload_field?.description ?? '', { timeout: 10000 }).catch(() => {});
    const server_error = await page.$eval('#target-error', (element) => (element.hidden ? '' : element.textContent));
    const next_to_upload = await page.evaluate(() => {
      const error = document.getElementById('target-error');
      return error.closest('section') === document.getElementById('file-input').closest('section');
    });
    check('bad upload: the server\'s message is shown under the upload box',
      upload_field !== undefined && server_error === upload_field.description && next_to_upload,
      `${JSON.stringify(upload_body)}; shown: ${server_error}`);
    await screenshot('bad-upload-server-message');

    check('no page errors', page_errors.length === 0, page_errors.join(' | '));
  } catch (error) {
    check('test ran to the end', false, error.message);
  } finally {
    if (context) await context.close().catch(() => {});
    await stop_server(server);
    check('no request left loopback', outside_requests.length === 0,
      outside_requests.length ? `blocked: ${outside_requests.join(', ')}` : 'every request went to 127.0.0.1');
    rmSync(work_dir, { recursive: true, force: true });
  }
}

const options = parse_arguments(process.argv.slice(2));
function kill_server_and_exit(reason) {
  console.error(`browser test: ${reason}; stopping`);
  if (running_server && running_server.exitCode === null) running_server.kill('SIGKILL');
  console.log(`browser: ${results.filter((result) => result.passed).length} passed, ${results.filter((result) => !result.passed).length + 1} failed`);
  process.exit(1);
}
const budget = setTimeout(() => kill_server_and_exit(`over its ${TOTAL_BUDGET_S} s budget`), TOTAL_BUDGET_S * 1000);
budget.unref();
process.on('SIGINT', () => kill_server_and_exit('interrupted'));
process.on('SIGTERM', () => kill_server_and_exit('terminated'));
await run(options);
const failed = results.filter((result) => !result.passed);
console.log(`browser test finished in ${elapsed_s()} s; screenshots and server.log in ${options.artifacts}`);
for (const result of failed) console.log(`  failed: ${result.name}${result.detail ? ` (${result.detail})` : ''}`);
console.log(`browser: ${results.length - failed.length} passed, ${failed.length} failed`);
process.exit(failed.length === 0 ? 0 : 1);
