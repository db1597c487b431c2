// Object File Format (OFF) text -> indexed triangle mesh, for the local preview of uploads and samples.

/**
 * Parses OFF text: header `OFF`, counts `#V #F #E`, #V lines `x y z`, #F lines `n i0 ... i(n-1)`
 * (anything after the n indices, such as a face colour, is ignored).
 * @param {string} text  the file's text
 * @returns {{positions: Float32Array, indices: Uint32Array}}  #V x 3 positions (file units) and
 *   #F x 3 zero-based vertex indices (polygons split into fans)
 * @throws {Error} naming what is wrong when the file is not a usable OFF mesh
 */
export function parse_off(text) {
  // Comments run from '#' to the end of the line; blank lines carry nothing.
  const lines = text
    .split(/\r?\n/)
    .map((line) => line.replace(/#.*/, '').trim())
    .filter((line) => line.length > 0);
  if (lines.length === 0 || !/^C?N?OFF\b/.test(lines[0])) throw new Error("not an OFF file (no 'OFF' header)");
  // The counts may share the header's line ("OFF 812 1620 0").
  const header_rest = lines[0].replace(/^C?N?OFF/, '').trim();
  let line_index = 1;
  const count_words = (header_rest.length > 0 ? header_rest : lines[line_index++] ?? '').split(/\s+/);
  const vertex_count = Number(count_words[0]);
  const face_count = Number(count_words[1]);
  if (!Number.isInteger(vertex_count) || !Number.isInteger(face_count) || vertex_count < 0 || face_count < 0)
    throw new Error('the counts line (vertices faces edges) is missing or not integers');
  if (vertex_count === 0) throw new Error('no vertices');
  if (face_count === 0) throw new Error('no faces');
  if (lines.length < line_index + vertex_count + face_count)
    throw new Error(`the file ends early: ${vertex_count} vertices and ${face_count} faces announced`);

  const positions = new Float32Array(vertex_count * 3);
  for (let v = 0; v < vertex_count; ++v) {
    const words = lines[line_index++].split(/\s+/);
    for (let k = 0; k < 3; ++k) {
      const value = Number(words[k]);
      if (!Number.isFinite(value)) throw new Error(`vertex ${v} has a coordinate that is not a number`);
      positions[v * 3 + k] = value;
    }
  }
  const indices = [];
  for (let f = 0; f < face_count; ++f) {
    const words = lines[line_index++].split(/\s+/).map(Number);
    const corner_count = words[0];
    if (!Number.isInteger(corner_count) || corner_count < 3 || words.length < corner_count + 1)
      throw new Error(`face ${f} has no valid corner list`);
    const corners = words.slice(1, corner_count + 1);
    for (const index of corners)
      if (!Number.isInteger(index) || index < 0 || index >= vertex_count)
        throw new Error(`face ${f} names vertex ${index}, which does not exist`);
    for (let k = 1; k + 1 < corners.length; ++k) indices.push(corners[0], corners[k], corners[k + 1]);
  }
  return { positions, indices: new Uint32Array(indices) };
}
