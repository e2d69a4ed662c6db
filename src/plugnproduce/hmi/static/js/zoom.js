// Pan and zoom of the chart picture: the mouse wheel zooms around the pointer, dragging pans,
// the buttons and keys (+, -, 0, arrows) do the same from the keyboard. A new picture starts fitted
// (a task chart's expanded step is then brought into view by charts.js).

import { $ } from "./dom.js";

const MIN_SCALE = 0.02;
const MAX_SCALE = 8;
const STEP = 1.25; // one button press or key
const PAN = 60; // pixels per arrow key
const view = { scale: 1, x: 0, y: 0 };
let frame = null;
let img = null;

function apply() {
  img.style.transform = `translate(${view.x}px, ${view.y}px) scale(${view.scale})`;
  Object.assign(frame.dataset, { scale: view.scale.toFixed(4), x: Math.round(view.x), y: Math.round(view.y) });
  $("#zoom-level").textContent = `${Math.round(view.scale * 100)} %`;
}

/** Show the whole picture, centred, never enlarged. */
export function fit() {
  const w = img.naturalWidth;
  const hgt = img.naturalHeight;
  if (!w || !hgt) return;
  const fw = frame.clientWidth;
  const fh = frame.clientHeight;
  view.scale = Math.min(fw / w, fh / hgt, 1);
  view.x = (fw - w * view.scale) / 2;
  view.y = (fh - hgt * view.scale) / 2;
  apply();
}

/** Show the part `box` ({x, y, w, h} in the picture's pixels) centred, as large as fits, never enlarged. */
export function focusOn(box) {
  const fw = frame.clientWidth;
  const fh = frame.clientHeight;
  view.scale = Math.max(MIN_SCALE, Math.min((0.95 * fw) / box.w, (0.95 * fh) / box.h, 1));
  view.x = fw / 2 - (box.x + box.w / 2) * view.scale;
  view.y = fh / 2 - (box.y + box.h / 2) * view.scale;
  apply();
}

/** Zoom by `factor`, keeping the point at (cx, cy) of the frame (default: its centre) where it is. */
export function zoomBy(factor, cx = frame.clientWidth / 2, cy = frame.clientHeight / 2) {
  const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, view.scale * factor));
  view.x = cx - ((cx - view.x) * scale) / view.scale;
  view.y = cy - ((cy - view.y) * scale) / view.scale;
  view.scale = scale;
  apply();
}

/** Move the picture by (dx, dy) pixels. */
export function panBy(dx, dy) {
  view.x += dx;
  view.y += dy;
  apply();
}

function onWheel(e) {
  e.preventDefault();
  const r = frame.getBoundingClientRect();
  const lines = e.deltaMode === 1 ? 40 : 1; // Firefox may count in lines
  zoomBy(Math.exp((-e.deltaY * lines) / 500), e.clientX - r.left, e.clientY - r.top);
}

function onPointerDown(e) {
  if (e.button !== 0) return;
  let last = { x: e.clientX, y: e.clientY };
  frame.setPointerCapture(e.pointerId);
  frame.classList.add("dragging");
  const move = (m) => {
    panBy(m.clientX - last.x, m.clientY - last.y);
    last = { x: m.clientX, y: m.clientY };
  };
  const up = () => {
    frame.removeEventListener("pointermove", move);
    frame.removeEventListener("pointerup", up);
    frame.removeEventListener("pointercancel", up);
    frame.classList.remove("dragging");
  };
  frame.addEventListener("pointermove", move);
  frame.addEventListener("pointerup", up);
  frame.addEventListener("pointercancel", up);
}

const KEYS = {
  "+": () => zoomBy(STEP), "=": () => zoomBy(STEP), "-": () => zoomBy(1 / STEP), 0: fit,
  ArrowLeft: () => panBy(PAN, 0), ArrowRight: () => panBy(-PAN, 0),
  ArrowUp: () => panBy(0, PAN), ArrowDown: () => panBy(0, -PAN),
};

function onKey(e) {
  const action = KEYS[e.key];
  if (!action || e.altKey || e.ctrlKey || e.metaKey) return;
  e.preventDefault();
  action();
}

/** Wire the chart frame: wheel, drag, keys and the zoom buttons; fit each picture as it loads. */
export function initZoom() {
  frame = $("#chart-frame");
  img = $("#chart-img");
  img.draggable = false;
  img.addEventListener("load", () => {
    $("#zoom-tools").hidden = false;
    frame.classList.add("has-chart"); // its full height, before fitting into it
    fit();
  });
  frame.addEventListener("wheel", onWheel, { passive: false });
  frame.addEventListener("pointerdown", onPointerDown);
  frame.addEventListener("keydown", onKey);
  $("#zoom-in").addEventListener("click", () => zoomBy(STEP));
  $("#zoom-out").addEventListener("click", () => zoomBy(1 / STEP));
  $("#zoom-fit").addEventListener("click", fit);
}
