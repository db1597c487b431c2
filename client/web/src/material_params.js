// Units of the rubber laws' constants (SPEC names), for every place the page shows them.

const MODULI = new Set(['mu', 'C1', 'C2', 'G']);

/** "MPa" for a modulus, "" for a dimensionless constant (k1, k2). */
export function param_unit(name) {
  return MODULI.has(name) ? 'MPa' : '';
}

/** A short label with its unit, e.g. "G (MPa)" or "k1 (dimensionless)". */
export function param_label(name) {
  return `${name} (${param_unit(name) || 'dimensionless'})`;
}

/** The constants' usual order (moduli first, as the SPEC strings write them). */
const ORDER = ['mu', 'C1', 'C2', 'G', 'k1', 'k2'];

/**
 * A material's params map as [name, value] pairs in the usual order (JSON maps come in any order).
 * @param {Object<string, number>} params
 * @returns {Array<[string, number]>}
 */
export function ordered_params(params) {
  const rank = (name) => (ORDER.includes(name) ? ORDER.indexOf(name) : ORDER.length);
  return Object.entries(params ?? {}).sort((a, b) => rank(a[0]) - rank(b[0]) || a[0].localeCompare(b[0]));
}
