// Error messages shown next to what caused them: each input or panel has an element (class "error")
// below it; the server's message goes into the one for the field it names.

/**
 * Shows a message in an error element (and marks the related control invalid for assistive tech).
 * @param {HTMLElement} element  the error element
 * @param {string} message  plain words; '' clears
 */
export function show_error(element, message) {
  element.textContent = message;
  element.hidden = message.length === 0;
  const control_id = element.dataset.for;
  if (control_id) {
    const control = document.getElementById(control_id);
    if (control) control.setAttribute('aria-invalid', message.length > 0 ? 'true' : 'false');
  }
}

/** Clears every error element inside a container. */
export function clear_errors(container) {
  for (const element of container.querySelectorAll('.error')) show_error(element, '');
}

/**
 * Which design-form field a service message is about, by the way the service words its messages
 * ("target_mesh: ...", "thickness must be ...", "material: ..."). Null when it names none.
 * @param {string} message
 * @returns {string|null}  'target', 'material', 'thickness', 'size', 'resolution', 'volume-ratio',
 *   'method' or 'max-time'
 */
export function design_field_for_message(message) {
  const rules = [
    [/^target_mesh\b/, 'target'],
    [/^material\b/, 'material'],
    [/^thickness\b/, 'thickness'],
    [/^size\b/, 'size'],
    [/^resolution\b/, 'resolution'],
    [/^(volume ratio|scale|give either a scale)\b/, 'volume-ratio'],
    [/^method\b/, 'method'],
    [/^max time\b/, 'max-time'],
  ];
  for (const [pattern, field] of rules) if (pattern.test(message)) return field;
  return null;
}
