// Unit tests of the page's DOM-free modules (client/web/src), run by node's test runner:
//   node --test tests/web/page_modules_test.mjs
// Needs client/web/node_modules (three, three-mesh-bvh), which the balloon_web build installs.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { SseParser } from '../../client/web/src/sse_parser.js';
import { parse_obj, write_obj } from '../../client/web/src/obj_parser.js';
import { parse_off } from '../../client/web/src/off_parser.js';
import { nice_upper_bound, ramp_color } from '../../client/web/src/color_map.js';
import { error_element_for_field, show_field_errors } from '../../client/web/src/field_errors.js';
import { mesh_format_for } from '../../client/web/src/mesh_loader.js';
import { ordered_params, param_label } from '../../client/web/src/material_params.js';
import { SurfaceDistance } from '../../client/web/src/surface_distance.js';
import { ApiClient, ApiError, base64_from_bytes, bytes_from_base64 } from '../../client/web/src/api_client.js';
import { format_error_mm } from '../../client/web/src/format.js';
import { CURVE_FIRST_RATIO, CURVE_LAST_RATIO_CAP, CURVE_POINTS, curve_spec_for_design } from '../../client/web/src/curve_request.js';
import { curve_summary_lines } from '../../client/web/src/curve_summary.js';
import { pressure_fall_line } from '../../client/web/src/pressure_fall_line.js';

test('SSE parser: events split across chunks, CRLF, comments and multi-line data', () => {
  const parser = new SseParser();
  const stream = ': keepalive\r\nevent: job\r\ndata: {"a":1}\r\n\r\nevent: end\ndata: line one\ndata: line two\n\n';
  const events = [];
  // Feed one character at a time: every boundary, including inside "\r\n", must be handled.
  for (const character of stream) events.push(...parser.feed(character));
  assert.equal(events.length, 2);
  assert.equal(events[0].type, 'job');
  assert.deepEqual(JSON.parse(events[0].data), { a: 1 });
  assert.equal(events[1].type, 'end');
  assert.equal(events[1].data, 'line one\nline two');
});

test('SSE parser: no event before its blank line, default type "message"', () => {
  const parser = new SseParser();
  assert.deepEqual(parser.feed('data: x\n'), []);
  const events = parser.feed('\n');
  assert.equal(events.length, 1);
  assert.equal(events[0].type, 'message');
  assert.equal(events[0].data, 'x');
});

test('OBJ: slashes, negative indices and polygons (fan), round trip through write_obj', () => {
  const mesh = parse_obj('v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\nf -4 -2 -1\n');
  assert.equal(mesh.positions.length, 12);
  assert.deepEqual(Array.from(mesh.indices), [0, 1, 2, 0, 2, 3, 0, 2, 3]);
  const again = parse_obj(write_obj(mesh.positions, mesh.indices));
  assert.deepEqual(Array.from(again.positions), Array.from(mesh.positions));
  assert.deepEqual(Array.from(again.indices), Array.from(mesh.indices));
});

test('OBJ: garbage, missing faces and bad indices are named', () => {
  assert.throws(() => parse_obj('this is not a mesh\n'), /no vertices/);
  assert.throws(() => parse_obj('v 0 0 0\nv 1 0 0\nv 0 1 0\n'), /no triangles/);
  assert.throws(() => parse_obj('v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n'), /line 4: vertex 7 does not exist/);
  assert.throws(() => parse_obj('v 0 zero 0\n'), /line 1: 'zero' is not a number/);
});

test('OFF: counts on the header line or the next, comments, quads', () => {
  const text = 'OFF\n# a square\n4 1 0\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n';
  const mesh = parse_off(text);
  assert.equal(mesh.positions.length / 3, 4);
  assert.deepEqual(Array.from(mesh.indices), [0, 1, 2, 0, 2, 3]);
  const same_line = parse_off('OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 255 0 0\n');
  assert.deepEqual(Array.from(same_line.indices), [0, 1, 2]);
  assert.throws(() => parse_off('PLY\n'), /not an OFF file/);
  assert.throws(() => parse_off('OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n'), /face 0 names vertex 5/);
});

test('mesh formats by extension', () => {
  assert.equal(mesh_format_for('a/b/Bunny.OBJ'), 'MESH_FORMAT_OBJ');
  assert.equal(mesh_format_for('x.glb'), 'MESH_FORMAT_GLB');
  assert.equal(mesh_format_for('notes.txt'), null);
});

test('legend bounds are the next round number at or above the value; ramp ends are the key colours', () => {
  assert.equal(nice_upper_bound(0.37), 0.4);
  assert.equal(nice_upper_bound(1.0), 1);
  assert.equal(nice_upper_bound(1.2), 1.5);
  assert.equal(nice_upper_bound(5.71), 6);
  assert.equal(nice_upper_bound(8.5), 10);
  assert.equal(nice_upper_bound(0.0123), 0.015);
  assert.equal(nice_upper_bound(0), 1);
  assert.deepEqual(ramp_color(0), [0.267, 0.005, 0.329]);
  assert.deepEqual(ramp_color(1), [0.993, 0.906, 0.144]);
  assert.deepEqual(ramp_color(2), ramp_color(1));
});

test('material constants come in the usual order with their units', () => {
  assert.deepEqual(ordered_params({ k2: 0.49, G: 0.18, k1: 3e-4 }).map(([name]) => name), ['G', 'k1', 'k2']);
  assert.deepEqual(ordered_params({ C2: 0.02, C1: 0.18 }).map(([name]) => name), ['C1', 'C2']);
  assert.equal(param_label('G'), 'G (MPa)');
  assert.equal(param_label('k1'), 'k1 (dimensionless)');
});

/**
 * The page's error elements as read from index.html itself (id, data-for, data-field), standing in for the
 * DOM: what querySelectorAll('.error[data-field]') finds in the real page.
 */
function page_error_elements() {
  const html = readFileSync(new URL('../../client/web/index.html', import.meta.url), 'utf8');
  const elements = [];
  for (const [, attributes] of html.matchAll(/<(?:p|span|div)\s([^>]*\bclass="error"[^>]*)>/g)) {
    const attribute = (name) => attributes.match(new RegExp(`\\b${name}="([^"]*)"`))?.[1];
    elements.push({ id: attribute('id'), dataset: { for: attribute('data-for'), field: attribute('data-field') },
                    textContent: '', hidden: true });
  }
  return {
    elements,
    querySelectorAll: (selector) => {
      assert.equal(selector, '.error[data-field]');
      return elements.filter((element) => element.dataset.field !== undefined);
    },
    by_id: (id) => elements.find((element) => element.id === id),
  };
}

test('a refused field is shown under its input, found by its path whatever the message says', async () => {
  // The API's error body as the gateway sends it; the words are arbitrary, so rewording a message in the
  // service changes nothing here. The ApiClient reads it through a stand-in fetch.
  const body = { error: { code: 'INVALID_ARGUMENT', message: 'xyzzy 42',
                          fields: [{ field: 'design.thickness_mm', description: 'plugh: any words at all' },
                                   { field: 'design.nozzle', description: 'no input for this one' }] } };
  const saved_fetch = globalThis.fetch;
  globalThis.fetch = async () => new Response(JSON.stringify(body), { status: 400, headers: { 'Content-Type': 'application/json' } });
  let error = null;
  try {
    await new ApiClient(() => '').submit_job({ design: {} });
  } catch (thrown) {
    error = thrown;
  } finally {
    globalThis.fetch = saved_fetch;
  }
  assert.ok(error instanceof ApiError);
  assert.equal(error.code, 'INVALID_ARGUMENT');
  assert.equal(error.fields.length, 2);

  const page = page_error_elements();
  const unplaced = show_field_errors(page, error.fields);
  const thickness = page.by_id('thickness-error');
  assert.equal(thickness.dataset.for, 'thickness-input');  // the element under the thickness input
  assert.equal(thickness.textContent, 'plugh: any words at all');
  assert.equal(thickness.hidden, false);
  for (const element of page.elements.filter((e) => e !== thickness)) assert.equal(element.hidden, true, element.id);
  // A field the page has no input for comes back, for the general message under the button.
  assert.deepEqual(unplaced.map((violation) => violation.field), ['design.nozzle']);
});

test('every design and fit field the page sends has an error element under its input', () => {
  const page = page_error_elements();
  const expected = {
    'design.target_mesh': 'drop-zone', 'design.material': 'material-select', 'design.thickness_mm': 'thickness-input',
    'design.size_mm': 'size-input', 'design.resolution': 'resolution-input', 'design.volume_ratio': 'volume-ratio-input',
    'design.scale': 'volume-ratio-input', 'design.max_time_s': 'max-time-input', 'design.method': 'method-select',
    'fit_material.data': 'fit-csv', 'fit_material.data[0].csv': 'fit-csv', 'fit_material.name': 'fit-name',
  };
  for (const [field, input] of Object.entries(expected))
    assert.equal(error_element_for_field(page, field)?.dataset.for, input, field);
  assert.equal(error_element_for_field(page, 'design.thickness'), null);  // a path, not a prefix of words
  assert.equal(error_element_for_field(page, 'priority'), null);
});

test('point-to-surface distance: exact on a scaled cube, zero on its own vertices', () => {
  // Unit cube [0,1]^3 as 12 triangles, scaled by 10 (file units -> mm) like a job's target.
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1]);
  const indices = new Uint32Array([
    0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7,
  ]);
  const distance = new SurfaceDistance(positions, indices, 10);
  const points = new Float32Array([
    5, 5, 25,   // above the top face: 15 mm
    5, 5, 5,    // centre: 5 mm to every face
    13, 14, 10, // off an edge (x = 10, y = 10 at z = 10): hypot(3, 4) = 5 mm
    10, 10, 10, // a vertex: 0
  ]);
  const result = distance.distances(points);
  const expected = [15, 5, 5, 0];
  for (let i = 0; i < expected.length; ++i) assert.ok(Math.abs(result[i] - expected[i]) < 1e-5, `point ${i}: ${result[i]} vs ${expected[i]}`);
});

test('base64 round trip of bytes, including large buffers', () => {
  const bytes = new Uint8Array(200000);
  for (let i = 0; i < bytes.length; ++i) bytes[i] = (i * 7919) % 256;
  const back = bytes_from_base64(base64_from_bytes(bytes.buffer));
  assert.equal(back.length, bytes.length);
  assert.ok(back.every((value, i) => value === bytes[i]));
  assert.equal(base64_from_bytes(new TextEncoder().encode('OFF\n').buffer), 'T0ZGCg==');
});

test('an error that was never computed (null) shows as a dash, not 0', () => {
  assert.equal(format_error_mm(null), '–');
  assert.equal(format_error_mm(undefined), '–');
  assert.equal(format_error_mm(-1), '–');
  assert.notEqual(format_error_mm(0), '–');
  assert.notEqual(format_error_mm(0.25), '–');
});

test('curve of a design: its rest mesh, material SPEC and thickness, to twice its volume ratio', () => {
  const result = {
    rest_mesh: { data: 'cmVzdA==', format: 'obj' },
    design_report: { volume_ratio: 8, material: 'hart-smith:G=0.12,k1=0.0005,k2=0.8', material_name: 'silicone', thickness_mm: 0.7 },
  };
  const spec = curve_spec_for_design(result);
  assert.deepEqual(spec.simulate.rest_mesh, { data: 'cmVzdA==', format: 'obj' });
  assert.deepEqual(spec.simulate.material, { spec: 'hart-smith:G=0.12,k1=0.0005,k2=0.8' });
  assert.equal(spec.simulate.thickness_mm, 0.7);
  assert.deepEqual(spec.simulate.curve.volume_ratio_range, { from: CURVE_FIRST_RATIO, to: 16 });
  assert.equal(spec.simulate.curve.points, CURVE_POINTS);
  result.design_report.volume_ratio = 100;
  assert.equal(curve_spec_for_design(result).simulate.curve.volume_ratio_range.to, CURVE_LAST_RATIO_CAP);
  // No designed balloon: no inflation (start_failed: volume_ratio absent), no rest mesh, no report.
  assert.throws(() => curve_spec_for_design({ ...result, design_report: { ...result.design_report, volume_ratio: undefined } }),
    /never inflated/);
  assert.throws(() => curve_spec_for_design({ design_report: result.design_report }), /no designed balloon/);
  assert.throws(() => curve_spec_for_design({ simulate_report: {} }), /no designed balloon/);
});

test('curve summary: converged count, range and each extremum in words; no maximum said so', () => {
  const report = {
    control: 'volume_ratio', range_from: 1.01, range_to: 16, vertices: 400, material_name: 'latex', thickness_mm: 0.5,
    points: [{ converged: true }, { converged: true }, { converged: true }, { converged: false }],
    extrema: [{ kind: 'maximum', volume_ratio: 2.43, pressure_kpa: 3.21 }, { kind: 'minimum', volume_ratio: 9.1, pressure_kpa: 2.2 }],
  };
  const lines = curve_summary_lines(report);
  assert.match(lines[0], /^3 of 4 equilibria converged, volume ratio 1\.01 to 16; 400 vertices; latex, 0\.5 mm thick\.$/);
  assert.match(lines[1], /^Pressure maximum: 3\.21 kPa at volume ratio 2\.43\. .*snaps/);
  assert.match(lines[2], /^Pressure minimum: 2\.2 kPa at volume ratio 9\.1\./);
  assert.equal(lines.length, 3);
  const rising = curve_summary_lines({ ...report, extrema: [] });
  assert.match(rising[1], /^No pressure maximum up to where the curve stopped/);
});

test('pressure fall: the band, the share of the design in it, and advice only when most of it is there', () => {
  const band = { from_stretch: 1.365, to_stretch: 3.966, from_volume_ratio: 2.543, to_volume_ratio: 62.38 };
  assert.equal(pressure_fall_line(undefined), '');
  assert.equal(pressure_fall_line(band),
    "This rubber's pressure falls as it stretches between stretch 1.365 and 3.966 (volume ratio 2.54 to 62.4).");
  const few = pressure_fall_line({ ...band, area_share: 0.12 });
  assert.match(few, /; 12 % of the inflated surface is stretched there\.$/);
  const most = pressure_fall_line({ ...band, area_share: 0.97 });
  assert.match(most, /97 % of the inflated surface .* bulge one at a time .* below 2\.54 or above 62\.4 keeps the sheet out of it\.$/);
  const forever = pressure_fall_line({ from_stretch: 1.383, from_volume_ratio: 2.646, area_share: 1 });
  assert.match(forever, /past stretch 1\.383 \(volume ratio 2\.65\).* below 2\.65 keeps/);
  assert.doesNotMatch(forever, /above/);
});
