// Small DOM helpers: build elements without innerHTML, announce changes to screen readers.

/**
 * Create an element: h("button", {type: "button", class: "x", onclick: fn}, "text", child...).
 * Attributes starting with "on" become listeners; `hidden`, `disabled` and friends take booleans.
 */
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs || {})) {
    if (value === undefined || value === null || value === false) continue;
    if (key.startsWith("on") && typeof value === "function") el.addEventListener(key.slice(2), value);
    else if (key === "class") el.className = value;
    else if (key === "dataset") Object.assign(el.dataset, value);
    else if (value === true) el.setAttribute(key, "");
    else el.setAttribute(key, String(value));
  }
  for (const child of children.flat()) {
    if (child === undefined || child === null || child === false) continue;
    el.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return el;
}

export const $ = (selector, root = document) => root.querySelector(selector);

/** Replace an element's children. */
export function fill(el, ...children) {
  el.replaceChildren(...children.flat().filter((c) => c !== undefined && c !== null && c !== false));
}

/** Say something to screen readers (and show it briefly in the header). */
export function announce(text) {
  const el = $("#announce");
  el.textContent = "";
  requestAnimationFrame(() => {
    el.textContent = text;
  });
}

/** A number as the descriptions write it: no trailing zeros. */
export function num(value) {
  return typeof value === "number" ? String(Number(value.toFixed(6))) : String(value);
}

/** A parameter value for reading: poses as "(x, y, z, rx, ry, rz)", with the unit. */
export function showValue(value, unit = "") {
  if (Array.isArray(value)) return `(${value.map(num).join(", ")})`;
  const u = unit && !Array.isArray(value) ? ` ${unit}` : "";
  return `${typeof value === "number" ? num(value) : String(value)}${u}`;
}
