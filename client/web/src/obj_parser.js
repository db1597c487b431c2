// Wavefront OBJ text -> indexed triangle mesh. Used for the local preview of uploads and for the
// rest/inflated meshes the server returns. Only `v` and `f` lines matter; polygons are split into fans.

/**
 * Parses OBJ text.
 * @param {string} text  the file's text
 * @returns {{positions: Float32Array, indices: Uint32Array}}  #V x 3 positions (file units, mm for the
 *   server's meshes) and #F x 3 zero-based vertex indices
 * @throws {Error} with a message naming the line when the file is not a usable triangle mesh
 */
export function parse_obj(text) {
  const positions = [];
  const indices = [];
  const lines = text.split(/\r?\n/);
  for (let line_number = 1; line_number <= lines.length; ++line_number) {
    const line = lines[line_number - 1].trim();
    if (line.length === 0 || line[0] === '#') continue;
    const words = line.split(/\s+/);
    if (words[0] === 'v') {
      if (words.length < 4) throw new Error(`line ${line_number}: a vertex needs three coordinates`);
      for (let k = 1; k <= 3; ++k) {
        const value = Number(words[k]);
        if (!Number.isFinite(value)) throw new Error(`line ${line_number}: '${words[k]}' is not a number`);
        positions.push(value);
      }
    } else if (words[0] === 'f') {
      if (words.length < 4) throw new Error(`line ${line_number}: a face needs at least three vertices`);
      const vertex_count = positions.length / 3;
      const corners = [];
      for (let k = 1; k < words.length; ++k) {
        // `f v/vt/vn`: only the part before the first slash is the vertex.
        const index = Number.parseInt(words[k].split('/')[0], 10);
        if (!Number.isInteger(index) || index === 0)
          throw new Error(`line ${line_number}: '${words[k]}' is not a vertex index`);
        // Negative indices count back from the last vertex read so far (OBJ spec).
        const zero_based = index > 0 ? index - 1 : vertex_count + index;
        if (zero_based < 0 || zero_based >= vertex_count)
          throw new Error(`line ${line_number}: vertex ${index} does not exist (${vertex_count} so far)`);
        corners.push(zero_based);
      }
      for (let k = 1; k + 1 < corners.length; ++k) indices.push(corners[0], corners[k], corners[k + 1]);
    }
  }
  if (positions.length === 0) throw new Error("no vertices (no 'v' lines)");
  if (indices.length === 0) throw new Error("no triangles (no 'f' lines)");
  return { positions: new Float32Array(positions), indices: new Uint32Array(indices) };
}

/**
 * Writes an indexed triangle mesh as OBJ text (1-based `f` lines).
 * @param {Float32Array|number[]} positions  #V x 3 positions (mm)
 * @param {Uint32Array|number[]} indices  #F x 3 zero-based vertex indices
 * @returns {string}
 */
export function write_obj(positions, indices) {
  const parts = [];
  for (let i = 0; i < positions.length; i += 3)
    parts.push(`v ${positions[i]} ${positions[i + 1]} ${positions[i + 2]}`);
  for (let i = 0; i < indices.length; i += 3)
    parts.push(`f ${indices[i] + 1} ${indices[i + 1] + 1} ${indices[i + 2] + 1}`);
  return parts.join('\n') + '\n';
}
