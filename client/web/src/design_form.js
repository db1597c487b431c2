// Step 3: the design settings, read into a DesignJob (proto balloon.v1.DesignJob, JSON mapping).
// Only "is it a number" is checked here; the server checks ranges and its message is shown by the field.
import { show_error } from './field_errors.js';

/** Form fields: id prefix, DesignJob field, whether it must be an integer, plain name with unit. */
const NUMBER_FIELDS = [
  ['thickness', 'thickness_mm', false, 'Thickness (mm)'],
  ['size', 'size_mm', false, 'Size (mm)'],
  ['resolution', 'resolution', true, 'Resolution (vertices)'],
  ['volume-ratio', 'volume_ratio', false, 'Volume ratio'],
  ['max-time', 'max_time_s', false, 'Max time (s)'],
];

export class DesignForm {
  /** @param {HTMLElement} section  the settings card (holds the inputs by id) */
  constructor(section) {
    this.m_section = section;
  }

  input(field) {
    return this.m_section.querySelector(`#${field}-input`) ?? this.m_section.querySelector(`#${field}-select`);
  }

  error_element(field) {
    return this.m_section.querySelector(`#${field}-error`);
  }

  /** Shows a message under a field ('thickness', 'size', 'resolution', 'volume-ratio', 'method', 'max-time'). */
  show_error(field, message) {
    const element = this.error_element(field);
    if (element) show_error(element, message);
  }

  /** The size asked for (mm); 0 keeps the file's size. NaN when not a number. */
  get size_mm() {
    return Number(this.input('size').value);
  }

  /**
   * The settings as a DesignJob without target and material, or null after showing which input is wrong.
   * @returns {object|null}
   */
  read() {
    const design = {};
    let ok = true;
    for (const [field, key, integer, label] of NUMBER_FIELDS) {
      const text = this.input(field).value.trim();
      const value = Number(text);
      this.show_error(field, '');
      if (text === '' || !Number.isFinite(value) || (integer && !Number.isInteger(value))) {
        this.show_error(field, `${label} must be ${integer ? 'a whole number' : 'a number'}.`);
        ok = false;
        continue;
      }
      design[key] = value;
    }
    this.show_error('method', '');
    const method = this.m_section.querySelector('#method-select').value;
    if (method) design.method = method;
    return ok ? design : null;
  }
}
