// The 3D viewer: three overlays (target, rest, inflated) in one scene with orbit controls. The inflated
// overlay shows the live shape while a job runs and the result's inflated mesh afterwards, coloured per
// vertex by its distance to the target. Renders on demand (after a change or a camera move), not in a loop.
import {
  AmbientLight,
  BufferAttribute,
  BufferGeometry,
  Color,
  DirectionalLight,
  DoubleSide,
  Mesh,
  MeshStandardMaterial,
  PerspectiveCamera,
  Scene,
  Sphere,
  Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

/** Background of the drawing area (the browser test counts pixels that differ from it). */
export const VIEWER_BACKGROUND = 0xf3f5f8;

/** The overlays, in drawing order. */
export const LAYERS = ['target', 'rest', 'inflated'];

/** sRGB channel (0..1) -> linear, since three.js treats vertex colours as linear. */
function linear_from_srgb(channel) {
  return channel <= 0.04045 ? channel / 12.92 : Math.pow((channel + 0.055) / 1.055, 2.4);
}

function make_material(layer) {
  switch (layer) {
    case 'target':
      // See-through so the inflated shape inside or around it stays visible; pushed back in depth so
      // where the inflated shape lies on the target (the goal) the inflated colours win, not a flicker.
      return new MeshStandardMaterial({
        color: 0x8a94a6, transparent: true, opacity: 0.28, depthWrite: false, side: DoubleSide, roughness: 0.9,
        polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 4,
      });
    case 'rest':
      return new MeshStandardMaterial({
        color: 0xe07b39, transparent: true, opacity: 0.75, side: DoubleSide, roughness: 0.7,
      });
    default:
      return new MeshStandardMaterial({ vertexColors: true, side: DoubleSide, roughness: 0.55, metalness: 0.0 });
  }
}

export class MeshViewer {
  /**
   * @param {HTMLElement} container  the element the canvas fills
   * @throws {Error} when the browser offers no WebGL
   */
  constructor(container) {
    this.m_container = container;
    this.m_renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.m_renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.m_renderer.setClearColor(new Color(VIEWER_BACKGROUND), 1);
    container.appendChild(this.m_renderer.domElement);
    this.m_renderer.domElement.setAttribute('aria-label', '3D view of the balloon');

    this.m_scene = new Scene();
    this.m_camera = new PerspectiveCamera(35, 1, 0.1, 1e5);
    this.m_camera.position.set(0, 0, 300);
    this.m_scene.add(this.m_camera);
    this.m_scene.add(new AmbientLight(0xffffff, 0.9));
    // Light rides with the camera so the side the user looks at is always lit.
    const key_light = new DirectionalLight(0xffffff, 1.6);
    key_light.position.set(0.5, 0.8, 1.0);
    this.m_camera.add(key_light);

    this.m_controls = new OrbitControls(this.m_camera, this.m_renderer.domElement);
    this.m_controls.addEventListener('change', () => this.request_render());

    this.m_meshes = {};
    this.m_visible = { target: true, rest: true, inflated: true };
    this.m_render_pending = false;

    this.m_resize_observer = new ResizeObserver(() => this.resize());
    this.m_resize_observer.observe(container);
    this.resize();
  }

  /** The canvas (for reading pixels). */
  get canvas() {
    return this.m_renderer.domElement;
  }

  resize() {
    const width = Math.max(1, this.m_container.clientWidth);
    const height = Math.max(1, this.m_container.clientHeight);
    this.m_renderer.setSize(width, height, true);
    this.m_camera.aspect = width / height;
    this.m_camera.updateProjectionMatrix();
    this.request_render();
  }

  /** Draws once at the next animation frame (several changes in one frame draw once). */
  request_render() {
    if (this.m_render_pending) return;
    this.m_render_pending = true;
    requestAnimationFrame(() => {
      this.m_render_pending = false;
      this.m_renderer.render(this.m_scene, this.m_camera);
    });
  }

  /**
   * Sets (or replaces) an overlay's mesh.
   * @param {string} layer  'target', 'rest' or 'inflated'
   * @param {Float32Array} positions  #V x 3 positions (mm)
   * @param {Uint32Array} indices  #F x 3 vertex indices
   * @param {number} [scale]  factor applied to the positions (the target's file units -> mm)
   */
  set_mesh(layer, positions, indices, scale = 1) {
    this.clear(layer);
    const geometry = new BufferGeometry();
    geometry.setAttribute('position', new BufferAttribute(Float32Array.from(positions), 3));
    geometry.setIndex(new BufferAttribute(Uint32Array.from(indices), 1));
    if (layer === 'inflated') {
      const white = new Float32Array(positions.length).fill(1);
      geometry.setAttribute('color', new BufferAttribute(white, 3));
    }
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    const mesh = new Mesh(geometry, make_material(layer));
    mesh.scale.setScalar(scale);
    mesh.renderOrder = LAYERS.indexOf(layer) === 0 ? 2 : 1;  // see-through target drawn last
    mesh.visible = this.m_visible[layer];
    this.m_meshes[layer] = mesh;
    this.m_scene.add(mesh);
    this.request_render();
  }

  /**
   * Moves the vertices of an overlay that keeps its connectivity (the live inflated shape).
   * @param {string} layer
   * @param {Float32Array|number[]} positions  #V x 3 positions (mm), same #V as set_mesh
   * @returns {boolean} false when the layer has no mesh of that size
   */
  update_positions(layer, positions) {
    const mesh = this.m_meshes[layer];
    if (!mesh) return false;
    const attribute = mesh.geometry.getAttribute('position');
    if (attribute.array.length !== positions.length) return false;
    attribute.array.set(positions);
    attribute.needsUpdate = true;
    mesh.geometry.computeVertexNormals();
    mesh.geometry.computeBoundingSphere();
    this.request_render();
    return true;
  }

  /**
   * Per-vertex colours of an overlay.
   * @param {string} layer
   * @param {Float32Array} colors  #V x 3 sRGB colours in 0..1
   */
  set_colors(layer, colors) {
    const mesh = this.m_meshes[layer];
    if (!mesh) return;
    const attribute = mesh.geometry.getAttribute('color');
    if (!attribute || attribute.array.length !== colors.length) return;
    for (let i = 0; i < colors.length; ++i) attribute.array[i] = linear_from_srgb(colors[i]);
    attribute.needsUpdate = true;
    this.request_render();
  }

  /** Whether an overlay has a mesh. */
  has(layer) {
    return Boolean(this.m_meshes[layer]);
  }

  /** Removes an overlay's mesh. */
  clear(layer) {
    const mesh = this.m_meshes[layer];
    if (!mesh) return;
    this.m_scene.remove(mesh);
    mesh.geometry.dispose();
    mesh.material.dispose();
    delete this.m_meshes[layer];
    this.request_render();
  }

  /** Removes every overlay. */
  clear_all() {
    for (const layer of LAYERS) this.clear(layer);
  }

  /** Shows or hides an overlay (kept when hidden). */
  set_visible(layer, visible) {
    this.m_visible[layer] = visible;
    if (this.m_meshes[layer]) this.m_meshes[layer].visible = visible;
    this.request_render();
  }

  /** Points the camera at everything loaded, from a three-quarter view. */
  frame_all() {
    const sphere = new Sphere();
    let first = true;
    for (const mesh of Object.values(this.m_meshes)) {
      const part = mesh.geometry.boundingSphere.clone();
      part.center.multiplyScalar(mesh.scale.x);
      part.radius *= mesh.scale.x;
      if (first) sphere.copy(part);
      else sphere.union(part);
      first = false;
    }
    if (first || !(sphere.radius > 0)) return;
    const half_fov = (this.m_camera.fov * Math.PI) / 360;
    const distance = (sphere.radius / Math.sin(half_fov)) * 1.15;
    const direction = new Vector3(0.55, 0.35, 1.0).normalize();
    this.m_camera.position.copy(sphere.center).addScaledVector(direction, distance);
    this.m_camera.near = Math.max(1e-3, distance / 1000);
    this.m_camera.far = distance * 20;
    this.m_controls.maxDistance = distance * 8;
    this.m_camera.updateProjectionMatrix();
    this.m_controls.target.copy(sphere.center);
    this.m_controls.update();
    this.request_render();
  }
}
