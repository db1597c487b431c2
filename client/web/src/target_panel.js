// Step 1: the target shape, from a dropped or picked file or from the bundled samples. Reads the file
// for the preview and keeps its bytes for the job; a file the browser cannot read is reported under the
// drop zone (and still sent, so the server's own message can be shown when the design starts).
import { show_error } from './field_errors.js';
import { ACCEPTED_EXTENSIONS, load_mesh, mesh_format_for } from './mesh_loader.js';
import { format_number } from './format.js';

/**
 * A chosen target.
 * @typedef {object} Target
 * @property {string} name  file name
 * @property {ArrayBuffer} bytes  the file's bytes (sent to the server)
 * @property {string|null} format  MeshFormat enum name, null for an unknown extension
 * @property {{positions: Float32Array, indices: Uint32Array}|null} mesh  the preview mesh (file units), null when unreadable
 */

/** Bounding-box diagonal of the vertices that faces use (the server drops unreferenced ones before scaling). */
export function bbox_diagonal(mesh) {
  const low = [Infinity, Infinity, Infinity];
  const high = [-Infinity, -Infinity, -Infinity];
  for (const index of mesh.indices)
    for (let k = 0; k < 3; ++k) {
      const value = mesh.positions[3 * index + k];
      if (value < low[k]) low[k] = value;
      if (value > high[k]) high[k] = value;
    }
  return Math.hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
}

export class TargetPanel {
  /**
   * @param {object} elements  drop_zone, file_input, sample_select, info, error
   * @param {(target: Target) => void} on_target  called when a new target has been read
   */
  constructor(elements, on_target) {
    this.m_elements = elements;
    this.m_on_target = on_target;
    this.m_target = null;
    elements.file_input.accept = ACCEPTED_EXTENSIONS.join(',');

    const zone = elements.drop_zone;
    zone.addEventListener('dragover', (event) => {
      event.preventDefault();
      zone.classList.add('dragging');
    });
    zone.addEventListener('dragleave', () => zone.classList.remove('dragging'));
    zone.addEventListener('drop', (event) => {
      event.preventDefault();
      zone.classList.remove('dragging');
      const file = event.dataTransfer?.files?.[0];
      if (file) this.take_file(file);
    });
    zone.addEventListener('keydown', (event) => {
      if (event.key === 'Enter' || event.key === ' ') {
        event.preventDefault();
        elements.file_input.click();
      }
    });
    elements.file_input.addEventListener('change', () => {
      const file = elements.file_input.files?.[0];
      if (file) this.take_file(file);
      elements.file_input.value = '';  // picking the same file again still fires `change`
    });
    elements.sample_select.addEventListener('change', () => {
      const option = elements.sample_select.selectedOptions[0];
      if (option && option.value) this.take_sample(option.value, option.textContent);
    });
  }

  /** The current target, or null. */
  get target() {
    return this.m_target;
  }

  /** Fills the sample list from /samples/samples.json (missing samples just leave the list empty). */
  async load_samples() {
    try {
      const response = await fetch('samples/samples.json');
      if (!response.ok) return;
      const samples = await response.json();
      for (const sample of samples) {
        const option = document.createElement('option');
        option.value = sample.file;
        option.textContent = `${sample.name} (${sample.vertices} vertices)`;
        this.m_elements.sample_select.appendChild(option);
      }
    } catch {
      // no samples in this build
    }
  }

  /** Shows a message under the drop zone ('' clears). */
  show_error(message) {
    show_error(this.m_elements.error, message);
  }

  async take_file(file) {
    this.m_elements.sample_select.value = '';
    await this.take_bytes(file.name, await file.arrayBuffer());
  }

  async take_sample(file_name, label) {
    this.show_error('');
    this.m_elements.info.textContent = `Loading ${label}…`;
    try {
      const response = await fetch(`samples/${encodeURIComponent(file_name)}`);
      if (!response.ok) throw new Error(`the page could not load it (HTTP ${response.status})`);
      await this.take_bytes(file_name, await response.arrayBuffer());
    } catch (error) {
      this.m_elements.info.textContent = '';
      this.show_error(`Sample ${label}: ${error.message}`);
    }
  }

  async take_bytes(name, bytes) {
    this.show_error('');
    const format = mesh_format_for(name);
    let mesh = null;
    if (format === null) {
      this.show_error(`${name}: the server reads ${ACCEPTED_EXTENSIONS.join(', ')} files; rename it or convert it.`);
    } else {
      try {
        mesh = await load_mesh(name, bytes);
      } catch (error) {
        this.show_error(`${name} is not a readable mesh: ${error.message}.`);
      }
    }
    this.m_target = { name, bytes, format, mesh };
    const kib = bytes.byteLength < 1024 ? `${bytes.byteLength} bytes` : `${format_number(bytes.byteLength / 1024, 3)} KiB`;
    this.m_elements.info.textContent = mesh
      ? `${name}: ${mesh.positions.length / 3} vertices, ${mesh.indices.length / 3} triangles, ` +
        `bounding-box diagonal ${format_number(bbox_diagonal(mesh))} (file units, read as mm), ${kib}`
      : `${name}: ${kib}`;
    this.m_on_target(this.m_target);
  }
}
