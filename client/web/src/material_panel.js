// Step 2: the material, chosen from GET /api/v1/materials (presets and the caller's own), with its law
// and constants shown in units.
import { show_error } from './field_errors.js';
import { format_number } from './format.js';
import { ordered_params, param_label } from './material_params.js';
import { pressure_fall_line } from './pressure_fall_line.js';

export class MaterialPanel {
  /**
   * @param {import('./api_client.js').ApiClient} api
   * @param {object} elements  select, info, error
   */
  constructor(api, elements) {
    this.m_api = api;
    this.m_elements = elements;
    this.m_materials = [];
    elements.select.addEventListener('change', () => this.show_details());
  }

  /** The chosen material's name ('' when none). */
  get selected_name() {
    return this.m_elements.select.value;
  }

  /** Shows a message under the material list ('' clears). */
  show_error(message) {
    show_error(this.m_elements.error, message);
  }

  /**
   * Reloads the list, keeping the choice (or choosing `select_name`).
   * @param {string} [select_name]
   */
  async refresh(select_name) {
    const keep = select_name ?? this.selected_name;
    try {
      this.m_materials = await this.m_api.list_materials();
      this.show_error('');
    } catch (error) {
      this.show_error(`The materials could not be loaded: ${error.message}`);
      return;
    }
    const select = this.m_elements.select;
    select.replaceChildren();
    const groups = [
      ['Presets', this.m_materials.filter((material) => material.preset)],
      ['Yours', this.m_materials.filter((material) => !material.preset)],
    ];
    for (const [label, materials] of groups) {
      if (materials.length === 0) continue;
      const group = document.createElement('optgroup');
      group.label = label;
      for (const material of materials) {
        const option = document.createElement('option');
        option.value = material.name;
        option.textContent = `${material.name} (${material.model})`;
        group.appendChild(option);
      }
      select.appendChild(group);
    }
    const names = this.m_materials.map((material) => material.name);
    if (names.includes(keep)) select.value = keep;
    else if (names.includes('latex')) select.value = 'latex';
    this.show_details();
  }

  show_details() {
    const info = this.m_elements.info;
    info.replaceChildren();
    const material = this.m_materials.find((candidate) => candidate.name === this.selected_name);
    if (!material) return;
    const law = document.createElement('p');
    law.textContent = `${material.model} law${material.preset ? ', built-in preset' : ''}`;
    info.appendChild(law);
    const list = document.createElement('dl');
    list.className = 'constants-inline';
    for (const [name, value] of ordered_params(material.params)) {
      const term = document.createElement('dt');
      term.textContent = param_label(name);
      const definition = document.createElement('dd');
      definition.textContent = format_number(value, 5);
      list.append(term, definition);
    }
    info.appendChild(list);
    if (material.description) {
      const description = document.createElement('p');
      description.className = 'hint';
      description.textContent = material.description.split('\n')[0];
      info.appendChild(description);
    }
    const band = pressure_fall_line(material.pressure_fall);
    if (band) {
      const hint = document.createElement('p');
      hint.className = 'hint';
      hint.textContent = `${band} Inflated to a volume ratio in that range, long or thin parts can bulge one at a time.`;
      info.appendChild(hint);
    }
  }
}
