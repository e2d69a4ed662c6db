// The cell (devices with class, skills, protocol, state; plug and unplug) and the process commands.

import { ApiError, del, get, post } from "./api.js";
import { explanationView } from "./derivation.js";
import { $, announce, fill, h } from "./dom.js";
import { changed, state } from "./state.js";

let addCommand = () => {};
let showChart = () => {};

/** Wire the panel: `onAdd(command)` opens the step dialog, `onChart(url, caption)` shows a picture. */
export function initCell({ onAdd, onChart }) {
  addCommand = onAdd;
  showChart = onChart;
  $("#plug-form").addEventListener("submit", async (e) => {
    e.preventDefault();
    const device = $("#plug-device").value;
    if (!device) return;
    const status = $("#plug-status");
    status.textContent = "";
    try {
      await post("/api/cell/devices", { device }, { auth: true });
    } catch (err) {  // said by the button, where the user looks
      announce(err.message);
      status.textContent = `Not plugged in: ${err.message.replace(/^error: /, "")}`;
    }
  });
}

function alertError(err) {
  const box = $("#verdict");
  fill(box, h("p", { class: "error" }, err instanceof ApiError ? err.message : String(err)));
}

async function unplug(device) {
  try {
    await del(`/api/cell/devices/${encodeURIComponent(device.id)}`, { auth: true });
  } catch (err) {
    alertError(err);
  }
}

function stateCell(device) {
  const concept = device.state_concept && device.state_concept !== device.state ? ` (${device.state_concept})` : "";
  return h("td", { class: "state", dataset: { device: device.id } }, h("span", { class: "badge" }, device.state || "?"), concept);
}

/** How each protocol is written: its own spelling, not upper case (OPC UA, UPnP). */
const PROTOCOL_NAMES = { xirp: "XIRP", upnp: "UPnP", opcua: "OPC UA" };

function deviceRow(device) {
  const actions = h("td", { class: "actions" },
    h("button", { type: "button", class: "quiet", "aria-label": `Show the state chart of ${device.id}`,
      onclick: () => showChart(device.chart, `Device State Chart of ${device.id}`) }, "Chart"),
    state.pluggable ? h("button", { type: "button", class: "quiet danger", "aria-label": `Unplug ${device.id}`,
      onclick: () => unplug(device) }, "Unplug") : null);
  return h("tr", { dataset: { device: device.id } },
    h("th", { scope: "row" }, h("span", { class: "device-id" }, device.id), h("span", { class: "device-label" }, device.label)),
    h("td", {}, device.classes.join(", ")),
    h("td", { class: "skills" }, device.skills.join(", ")),
    h("td", { class: "protocol" }, h("span", { class: `proto proto-${device.protocol}` }, PROTOCOL_NAMES[device.protocol] || device.protocol),
      device.endpoint ? h("code", { class: "endpoint" }, device.endpoint) : null),
    stateCell(device),
    actions);
}

/** Show the cell as it is now. */
export function renderCell() {
  const cell = state.cell;
  $("#cell-name").textContent = cell ? cell.name : "…";
  const devices = cell ? cell.devices : [];
  fill($("#devices tbody"), devices.map(deviceRow));
  $("#devices").hidden = devices.length === 0;
  $("#devices-empty").hidden = devices.length > 0;
  const refused = cell && cell.refused ? cell.refused : [];
  fill($("#refused-list"), refused.map((r) => h("li", { dataset: { udn: r.udn } },
    h("span", { class: "device-id" }, r.udn), " at ", h("code", {}, r.url), ": ", r.reason)));
  $("#refused").hidden = refused.length === 0;
  const present = new Set(devices.map((d) => d.id));
  const pluggable = state.catalogue.filter((d) => !present.has(d.id));
  $("#plug-form").hidden = !state.pluggable || pluggable.length === 0;
  fill($("#plug-device"), pluggable.map((d) => h("option", { value: d.id }, `${d.id} (${d.classes.join(", ")})`)));
}

/** Update one device's state cell (from a run or the live cell). */
export function renderDeviceState(device, stateName, concept) {
  const d = state.cell && state.cell.devices.find((x) => x.id === device);
  if (d) {
    d.state = stateName;
    d.state_concept = concept;
  }
  const cell = document.querySelector(`#devices td.state[data-device="${CSS.escape(device)}"]`);
  if (cell && d) cell.replaceWith(stateCell(d));
}

function bindingsText(offer) {
  if (offer.binding_count !== 1) return `${offer.binding_count.toLocaleString("en")} ways to bind its roles`;
  return Object.entries(offer.bindings[0]).map(([role, dev]) => `${role}: ${dev}`).join(", ");
}

async function toggleWhy(button, box, command) {
  const open = button.getAttribute("aria-expanded") === "true";
  button.setAttribute("aria-expanded", String(!open));
  box.hidden = open;
  if (open || box.dataset.loaded) return;
  fill(box, h("p", { class: "hint" }, "asking the reasoner…"));
  try {
    const ex = await get(`/api/commands/${encodeURIComponent(command)}/explanation`);
    box.dataset.loaded = "1";
    fill(box, explanationView(ex, applyCounterfactual, canApply));
  } catch (err) {
    fill(box, h("p", { class: "error" }, err.message));
  }
}

/** A counterfactual the page can carry out: plug a catalogue device in (after unplugging the one it replaces). */
function canApply(c) {
  return state.pluggable && (c.kind === "add_device" || c.kind === "swap_device");
}

async function applyCounterfactual(c) {
  try {
    if (c.replaces) await del(`/api/cell/devices/${encodeURIComponent(c.replaces)}`, { auth: true });
    for (const device of c.devices) await post("/api/cell/devices", { device }, { auth: true });
    announce(`Applied: ${c.text}.`);
  } catch (err) {
    announce(err.message);
    alertError(err);
  }
}

/** Show the offered process commands and, behind "Why not?", the others. */
export function renderCommands() {
  const commands = state.commands;
  const offered = commands ? commands.offered : [];
  fill($("#offered"), offered.map((o) => h("li", { dataset: { command: o.command } },
    h("div", { class: "cmd" }, h("span", { class: "cmd-label" }, o.label), h("code", {}, o.command)),
    h("span", { class: "cmd-binding" }, bindingsText(o)),
    h("button", { type: "button", class: "add", "aria-label": `Add ${o.label} to the task`,
      onclick: () => addCommand(o.command) }, "Add"))));
  const notOffered = commands ? commands.not_offered : [];
  fill($("#not-offered"), notOffered.map((n) => {
    const id = `why-${n.command}`;
    const box = h("div", { id, class: "why", hidden: true });
    const button = h("button", { type: "button", class: "quiet", "aria-expanded": "false", "aria-controls": id,
      "aria-label": `Why is ${n.label} not offered?`, onclick: () => toggleWhy(button, box, n.command) }, "Why not?");
    return h("li", { dataset: { command: n.command } },
      h("div", { class: "cmd" }, h("span", { class: "cmd-label" }, n.label), h("code", {}, n.command)), button, box);
  }));
}

/** Take in a "cell" event (or the first load): the cell, its commands, and what changed. */
export function takeCell(data) {
  const before = new Set((state.commands ? state.commands.offered : []).map((o) => o.command));
  state.cell = data.cell;
  state.commands = data.commands;
  renderCell();
  renderCommands();
  if (data.change) {
    const after = new Set((state.commands ? state.commands.offered : []).map((o) => o.command));
    const gone = [...before].filter((c) => !after.has(c));
    const come = [...after].filter((c) => !before.has(c));
    const verb = data.change.kind === "plug" ? "plugged in" : data.change.kind === "unplug" ? "unplugged" : data.change.kind;
    const parts = [`${data.change.device} ${verb}.`];
    if (come.length) parts.push(`Now offered: ${come.join(", ")}.`);
    if (gone.length) parts.push(`No longer offered: ${gone.join(", ")}.`);
    announce(parts.join(" "));
  }
  changed("cell", data);
}
