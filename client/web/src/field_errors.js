// Error messages shown next to what caused them: each input or panel has an element (class "error")
// below it. A refused request names its bad fields by path (the API's `error.fields`, from the service's
// google.rpc.BadRequest); an error element claims the paths it shows in `data-field` (space-separated),
// so a message lands under its input whatever its wording.

/**
 * Shows a message in an error element (and marks the related control invalid for assistive tech).
 * @param {HTMLElement} element  the error element
 * @param {string} message  plain words; '' clears
 */
export function show_error(element, message) {
  element.textContent = message;
  element.hidden = message.length === 0;
  const control_id = element.dataset.for;
  if (control_id && typeof document !== 'undefined') {
    const control = document.getElementById(control_id);
    if (control) control.setAttribute('aria-invalid', message.length > 0 ? 'true' : 'false');
  }
}

/** Clears every error element inside a container. */
export function clear_errors(container) {
  for (const element of container.querySelectorAll('.error')) show_error(element, '');
}

/**
 * Whether an error element that claims `claimed` (a data-field path) shows an error about `field`: the same
 * path, or a part of it ("fit_material.data" shows "fit_material.data[0].csv").
 */
function claims(claimed, field) {
  return field === claimed || field.startsWith(`${claimed}.`) || field.startsWith(`${claimed}[`);
}

/**
 * The error element under the input a field path names, or null when no element claims it.
 * @param {ParentNode} root  where to look (the document, or a panel)
 * @param {string} field  e.g. "design.thickness_mm"
 * @returns {HTMLElement|null}
 */
export function error_element_for_field(root, field) {
  for (const element of root.querySelectorAll('.error[data-field]'))
    if (element.dataset.field.split(/\s+/).some((claimed) => claims(claimed, field))) return element;
  return null;
}

/**
 * Shows each field violation under the input it names (several violations of one element are joined).
 * @param {ParentNode} root  where the error elements are
 * @param {{field: string, description: string}[]} fields  the API's `error.fields`
 * @returns {{field: string, description: string}[]}  the violations no element claims (for a general message)
 */
export function show_field_errors(root, fields) {
  const unplaced = [];
  const shown = new Map();
  for (const violation of fields ?? []) {
    const element = error_element_for_field(root, String(violation.field ?? ''));
    if (!element) {
      unplaced.push(violation);
      continue;
    }
    const text = [...(shown.get(element) ?? []), String(violation.description ?? '')];
    shown.set(element, text);
    show_error(element, text.join(' '));
  }
  return unplaced;
}
