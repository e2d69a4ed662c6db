// The Goal view's form: a goal's name, the commands to achieve with the parameters the goal fixes, the
// outcome to repeat until and the states to leave devices in. It writes the goal as YAML into the Goal
// view's text (the form `pnp plan` reads), on every change; the text may also be edited by hand.

import { $, fill, h, num } from "./dom.js";
import { on, state } from "./state.js";

/** The bin-emptying goal (descriptions/goals/empty-the-bin.yaml), which the form starts with. */
const EXAMPLE = {
  name: "empty-the-bin",
  achieve: [{ command: "place", params: { place_pose: [0.6, -0.2, 0.1, 0, 180, 0] } }],
  until: "BinEmpty",
  end: [["gripper", "Open"]],
};

const PLAIN = /^[A-Za-z_][A-Za-z0-9_.-]*$/;
const RESERVED = /^(true|false|yes|no|on|off|null|y|n)$/i;

/** A value as YAML: numbers and booleans as they are, a list in brackets, a string plain when it reads back
 * as itself, else quoted (JSON's quoting is YAML's). */
function scalar(value) {
  if (Array.isArray(value)) return `[${value.map(scalar).join(", ")}]`;
  if (typeof value === "number" || typeof value === "boolean") return String(value);
  const text = String(value);
  return PLAIN.test(text) && !RESERVED.test(text) ? text : JSON.stringify(text);
}

/** The goal as YAML, in the shape of the goal files. */
export function goalYaml(goal) {
  const lines = [`goal: ${scalar(goal.name)}`, goal.achieve.length ? "achieve:" : "achieve: []"];
  for (const item of goal.achieve) {
    lines.push(`  - command: ${scalar(item.command)}`);
    const params = Object.entries(item.params);
    if (params.length) lines.push(`    params: {${params.map(([n, v]) => `${n}: ${scalar(v)}`).join(", ")}}`);
  }
  if (goal.until) lines.push(`until: ${scalar(goal.until)}`);
  if (goal.end.length) lines.push(`end: {${goal.end.map(([d, c]) => `${scalar(d)}: ${scalar(c)}`).join(", ")}}`);
  return `${lines.join("\n")}\n`;
}

/** A parameter's text as the value the goal fixes (undefined: left to the planner). */
function valueOf(text, p) {
  const t = text.trim();
  if (!t) return undefined;
  if (p.datatype === "pose") {
    const parts = t.split(/[\s,]+/).map(Number);
    return parts.every(Number.isFinite) ? parts : t;
  }
  if (p.datatype === "decimal" || p.datatype === "integer") return Number.isFinite(Number(t)) ? Number(t) : t;
  if (p.datatype === "boolean" && /^(true|false)$/.test(t)) return t === "true";
  return t;
}

function textOf(value) {
  if (value === undefined || value === null) return "";
  return Array.isArray(value) ? value.map(num).join(" ") : String(value);
}

/** A choice among `choices` ([value, text]); the chosen value is among them even when the cell has it no more. */
function select(attrs, choices, chosen) {
  const all = chosen && !choices.some(([value]) => value === chosen) ? [[chosen, chosen], ...choices] : choices;
  return h("select", attrs, all.map(([value, text]) => h("option", { value, selected: value === chosen }, text)));
}

function paramFields(command, params, row) {
  const process = state.processes.get(command);
  return ((process && process.parameters) || []).map((p) => {
    const hint = p.default !== null && p.default !== undefined ? `planned; default ${textOf(p.default)}` : "planned";
    return h("label", { class: "goal-param" }, `${p.label}${p.unit ? ` (${p.unit})` : ""} `,
      h("input", { type: "text", name: p.name, value: textOf(params[p.name]), placeholder: hint, autocomplete: "off",
        "aria-label": `command ${row + 1}: ${p.label}`, dataset: { param: p.name } }));
  });
}

function achieveItem(item, row) {
  const commands = [...state.processes.keys()].sort().map((c) => [c, c]);
  return h("li", { class: "goal-command", dataset: { row } },
    select({ class: "command", "aria-label": `command ${row + 1}` }, commands, item.command),
    h("button", { type: "button", class: "remove", dataset: { remove: "achieve" } }, "Remove"),
    h("div", { class: "goal-params" }, paramFields(item.command, item.params, row)));
}

function endItem([device, concept], row) {
  const devices = ((state.cell && state.cell.devices) || []).map((d) => [d.id, d.id]);
  const found = ((state.cell && state.cell.devices) || []).find((d) => d.id === device);
  const concepts = ((found && found.concepts) || []).map((c) => [c, c]);
  return h("li", { class: "goal-end", dataset: { row } },
    select({ class: "device", "aria-label": `end state ${row + 1}: device` }, devices, device),
    select({ class: "concept", "aria-label": `end state ${row + 1}: state` }, concepts, concept),
    h("button", { type: "button", class: "remove", dataset: { remove: "end" } }, "Remove"));
}

function outcomes() {
  const all = new Set();
  for (const p of state.processes.values()) (p.outcome_choices || []).forEach((c) => all.add(c.outcome));
  return [["", "(none: a straight plan)"], ...[...all].sort().map((o) => [o, o])];
}

let goal = structuredClone(EXAMPLE);

/** The goal as the form shows it now. */
function collect() {
  const achieve = [...document.querySelectorAll("#goal-achieve li")].map((li) => {
    const command = $("select.command", li).value;
    const process = state.processes.get(command);
    const params = {};
    for (const p of (process && process.parameters) || []) {
      const input = $(`input[data-param="${p.name}"]`, li);
      const value = input ? valueOf(input.value, p) : undefined;
      if (value !== undefined) params[p.name] = value;
    }
    return { command, params };
  });
  const end = [...document.querySelectorAll("#goal-end li")].map((li) => [$("select.device", li).value,
    $("select.concept", li).value]);
  return { name: $("#goal-name").value.trim(), achieve, until: $("#goal-until").value, end };
}

function render() {
  $("#goal-name").value = goal.name;
  fill($("#goal-achieve"), goal.achieve.map(achieveItem));
  fill($("#goal-until"), outcomes().map(([value, text]) => h("option", { value, selected: value === goal.until }, text)));
  $("#goal-until").value = goal.until;
  fill($("#goal-end"), goal.end.map(endItem));
}

function write() {
  $("#goal-text").value = goalYaml(goal);
}

/** A change in the form: re-read it, redraw what depends on a choice (a command's parameters, a device's
 * states), and write the YAML. */
function changedForm(event) {
  goal = collect();
  if (event.target.matches("select.command, select.device")) render();
  write();
}

function edit(event) {
  const button = event.target.closest("button");
  if (!button) return;
  goal = collect();
  if (button.id === "goal-add-command") goal.achieve.push({ command: [...state.processes.keys()].sort()[0], params: {} });
  else if (button.id === "goal-add-end") {
    const device = ((state.cell && state.cell.devices) || [])[0];
    if (device) goal.end.push([device.id, (device.concepts || [])[0] || ""]);
  } else if (button.dataset.remove) {
    const row = Number(button.closest("li").dataset.row);
    goal[button.dataset.remove].splice(row, 1);
  } else return;
  render();
  write();
}

/** Wire the form; it starts with the bin-emptying goal, written into the YAML. */
export function initGoalForm() {
  const box = $("#goal-form");
  box.addEventListener("input", changedForm);
  box.addEventListener("change", changedForm);
  box.addEventListener("click", edit);
  let devices = "";
  on("cell", () => { // a device plugged in or out: the end states' choices change
    const now = ((state.cell && state.cell.devices) || []).map((d) => d.id).join(" ");
    if (now === devices) return;
    devices = now;
    goal = collect();
    render();
  });
  render();
  write();
}
