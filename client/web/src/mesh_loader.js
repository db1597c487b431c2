// A mesh file's bytes -> its wire format (MeshFormat enum name) and an indexed triangle mesh for the
// local preview. The server reads the same bytes itself; this copy is only for drawing the target and
// measuring distances to it in the browser.
import { BufferGeometry, Mesh } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { PLYLoader } from 'three/examples/jsm/loaders/PLYLoader.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { mergeVertices } from 'three/examples/jsm/utils/BufferGeometryUtils.js';
import { parse_obj } from './obj_parser.js';
import { parse_off } from './off_parser.js';

/** File extension -> MeshFormat enum name of the API (proto balloon.v1.MeshFormat). */
export const MESH_FORMAT_BY_EXTENSION = {
  obj: 'MESH_FORMAT_OBJ',
  stl: 'MESH_FORMAT_STL',
  ply: 'MESH_FORMAT_PLY',
  off: 'MESH_FORMAT_OFF',
  gltf: 'MESH_FORMAT_GLTF',
  glb: 'MESH_FORMAT_GLB',
};

/** What the file picker offers. */
export const ACCEPTED_EXTENSIONS = Object.keys(MESH_FORMAT_BY_EXTENSION).map((extension) => '.' + extension);

/**
 * The MeshFormat enum name for a file name, or null when the extension is not one the server reads.
 * @param {string} file_name
 * @returns {string|null}
 */
export function mesh_format_for(file_name) {
  const match = /\.([A-Za-z0-9]+)$/.exec(file_name);
  return match ? MESH_FORMAT_BY_EXTENSION[match[1].toLowerCase()] ?? null : null;
}

/** BufferGeometry (indexed or not) -> indexed mesh with shared vertices. */
function indexed_mesh_from_geometry(geometry) {
  // Only positions decide which corners are one vertex (normals, uvs and colours would split them).
  const bare = new BufferGeometry();
  bare.setAttribute('position', geometry.getAttribute('position'));
  if (geometry.getIndex()) bare.setIndex(geometry.getIndex());
  const welded = mergeVertices(bare, 1e-6);
  const positions = Float32Array.from(welded.getAttribute('position').array);
  const indices = Uint32Array.from(welded.getIndex().array);
  return { positions, indices };
}

/** glTF scene -> all its triangle meshes in world coordinates, as one indexed mesh. */
function indexed_mesh_from_scene(scene) {
  scene.updateMatrixWorld(true);
  const positions = [];
  const indices = [];
  scene.traverse((object) => {
    if (!(object instanceof Mesh)) return;
    const geometry = object.geometry.clone().applyMatrix4(object.matrixWorld);
    const part = indexed_mesh_from_geometry(geometry);
    const offset = positions.length / 3;
    positions.push(...part.positions);
    for (const index of part.indices) indices.push(index + offset);
  });
  if (indices.length === 0) throw new Error('the glTF file holds no triangle mesh');
  return { positions: new Float32Array(positions), indices: new Uint32Array(indices) };
}

/**
 * Reads a mesh file for the preview.
 * @param {string} file_name  used for the format (by extension)
 * @param {ArrayBuffer} bytes  the file's bytes
 * @returns {Promise<{positions: Float32Array, indices: Uint32Array}>}  #V x 3 positions (file units)
 *   and #F x 3 zero-based indices
 * @throws {Error} with a plain message when the file cannot be read as a triangle mesh
 */
export async function load_mesh(file_name, bytes) {
  const format = mesh_format_for(file_name);
  if (format === null)
    throw new Error(`'${file_name}' is not a mesh file the server reads (${ACCEPTED_EXTENSIONS.join(', ')})`);
  let mesh;
  switch (format) {
    case 'MESH_FORMAT_OBJ':
      mesh = parse_obj(new TextDecoder().decode(bytes));
      break;
    case 'MESH_FORMAT_OFF':
      mesh = parse_off(new TextDecoder().decode(bytes));
      break;
    case 'MESH_FORMAT_STL':
      mesh = indexed_mesh_from_geometry(new STLLoader().parse(bytes));
      break;
    case 'MESH_FORMAT_PLY':
      mesh = indexed_mesh_from_geometry(new PLYLoader().parse(bytes));
      break;
    default: {
      const gltf = await new GLTFLoader().parseAsync(bytes, '');
      mesh = indexed_mesh_from_scene(gltf.scene);
    }
  }
  if (mesh.indices.length === 0) throw new Error('the file holds no triangles');
  for (const value of mesh.positions)
    if (!Number.isFinite(value)) throw new Error('the file has coordinates that are not finite numbers');
  return mesh;
}
