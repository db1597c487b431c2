// Distance from points to the target surface, for the per-vertex error colouring. Exact point-to-
// triangle distances, made fast by a bounding-volume hierarchy (three-mesh-bvh) built once per target.
import { BufferAttribute, BufferGeometry, Vector3 } from 'three';
import { MeshBVH } from 'three-mesh-bvh';

export class SurfaceDistance {
  /**
   * @param {Float32Array} positions  target #V x 3 positions (file units)
   * @param {Uint32Array} indices  target #F x 3 vertex indices
   * @param {number} scale  factor that takes the file's coordinates to the job's mm (the server scales
   *   the target about the origin to the asked bounding-box diagonal)
   */
  constructor(positions, indices, scale) {
    const scaled = new Float32Array(positions.length);
    for (let i = 0; i < positions.length; ++i) scaled[i] = positions[i] * scale;
    const geometry = new BufferGeometry();
    geometry.setAttribute('position', new BufferAttribute(scaled, 3));
    // The BVH reorders the index buffer it is given, so it gets its own copy.
    geometry.setIndex(new BufferAttribute(Uint32Array.from(indices), 1));
    this.m_bvh = new MeshBVH(geometry);
    this.m_point = new Vector3();
    this.m_hit = {};
  }

  /**
   * Distance from each point to the nearest point of the target surface.
   * @param {Float32Array|number[]} points  #P x 3 positions (mm)
   * @returns {Float32Array}  #P distances (mm)
   */
  distances(points) {
    const count = Math.floor(points.length / 3);
    const result = new Float32Array(count);
    for (let i = 0; i < count; ++i) {
      this.m_point.set(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
      const hit = this.m_bvh.closestPointToPoint(this.m_point, this.m_hit);
      result[i] = hit ? hit.distance : NaN;
    }
    return result;
  }
}
