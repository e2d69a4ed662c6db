// The parameter dialog of a process command, generated from its process description: a field per
// parameter (type, unit, range, default) and a device choice per role where several devices fit.
// A parameter may take an earlier named step's output instead of a value (the outputs whose datatype
// and unit fit, as the server describes them); a step whose process gives outputs may be named.
// A step may lie in a branch: it takes the outputs of the steps before it on every path to it.
// Values are refused with the messages of the task shapes: the dialog validates the task through
// the API (as `pnp validate` would) before it lets the step in. A parameter whose quantity a device reports
// has "Teach" beside it (teach.js).

import { post } from "./api.js";
import { $, fill, h, num } from "./dom.js";
import { earlierOnPath, numberOf, rowOf, withStep } from "./places.js";
import { offer, state, taskBody } from "./state.js";
import { teachButton } from "./teach.js";

const POSE_AXES = ["x", "y", "z", "rx", "ry", "rz"];

function rangeText(p) {
  const unit = p.unit ? ` ${p.unit}` : "";
  const parts = [];
  if (p.min !== null && p.max !== null) parts.push(`${num(p.min)} to ${num(p.max)}${unit}`);
  else if (p.min !== null) parts.push(`at least ${num(p.min)}${unit}`);
  else if (p.max !== null) parts.push(`at most ${num(p.max)}${unit}`);
  if (p.default !== null && p.default !== undefined) {
    parts.push(`default ${Array.isArray(p.default) ? p.default.map(num).join(" ") : num(p.default)}`);
  }
  return parts.join("; ");
}

function numberInput(id, p, value, label) {
  return h("input", {
    id, name: p.name, type: "number", step: p.datatype === "integer" ? "1" : "any",
    inputmode: p.datatype === "integer" ? "numeric" : "decimal",
    min: p.min ?? undefined, max: p.max ?? undefined, value: value ?? "", "aria-label": label,
    "aria-describedby": `${id}-hint ${id}-error`,
  });
}

/** The outputs of the named steps before `at` on every path to it a parameter may take: [{from, output, text}]. */
function sources(p, at) {
  const out = [];
  for (const { step: s, place } of earlierOnPath(at.steps, at.place)) {
    const process = state.processes.get(s.command);
    if (!s.name || !process) continue;
    for (const o of process.outputs || []) {
      if (o.datatype === p.datatype && (o.unit || "") === (p.unit || "")) {
        out.push({ from: s.name, output: o.name, text: `${o.label} of step ${numberOf(at.steps, place)} (${s.name})` });
      }
    }
  }
  return out;
}

const ENTERED = "";

function sourceField(p, value, found) {
  const link = value && value.from ? `${value.from}.${value.output}` : ENTERED;
  const options = found.map((f) => [`${f.from}.${f.output}`, `from ${f.text}`]);
  if (link !== ENTERED && !options.some(([v]) => v === link)) options.push([link, `from ${value.output} of ${value.from}`]);
  const select = h("select", { id: `param-${p.name}-source`, class: "source", "aria-label": `${p.label}: value from` },
    h("option", { value: ENTERED, selected: link === ENTERED }, "entered here"),
    options.map(([v, text]) => h("option", { value: v, selected: v === link }, text)));
  return h("label", { class: "source-choice" }, "Value ", select);
}

function showSource(box) {
  const select = box.querySelector("select.source");
  const linked = Boolean(select && select.value !== ENTERED);
  box.classList.toggle("linked", linked);
  box.querySelectorAll("input").forEach((i) => { i.disabled = linked; });
}

function paramField(p, value, at, root) {
  const found = sources(p, at);
  const box = valueField(p, value && value.from ? undefined : value);
  const teach = teachButton(p, box, root);
  if (teach) box.append(teach);
  if (found.length || (value && value.from)) {
    box.append(sourceField(p, value, found));
    box.querySelector("select.source").addEventListener("change", () => showSource(box));
    showSource(box);
  }
  return box;
}

function nameField(process, previous) {
  if (!(process.outputs || []).length) return null;
  return h("div", { class: "field step-name" },
    h("label", { for: "step-name" }, "Step name"),
    h("input", { id: "step-name", name: "step-name", type: "text", maxlength: 200, autocomplete: "off",
      pattern: "[A-Za-z_][A-Za-z0-9_]*", value: (previous && previous.name) || "", "aria-describedby": "step-name-hint" }),
    h("span", { id: "step-name-hint", class: "hint" },
      `later steps take its ${process.outputs.map((o) => o.label).join(", ")} by this name`));
}

function valueField(p, value) {
  const id = `param-${p.name}`;
  const hint = h("span", { id: `${id}-hint`, class: "hint" }, [p.datatype, rangeText(p)].filter(Boolean).join(" · "));
  const error = h("span", { id: `${id}-error`, class: "error field-error" });
  const unit = p.unit && p.datatype !== "pose" ? h("span", { class: "unit" }, p.unit) : null;
  if (p.datatype === "pose") {
    const pose = Array.isArray(value) ? value : Array.isArray(p.default) ? p.default : [];
    return h("fieldset", { class: "field pose", dataset: { param: p.name, kind: "pose" }, "aria-describedby": `${id}-hint ${id}-error` },
      h("legend", {}, p.label, p.unit ? h("span", { class: "unit" }, ` (${p.unit.replace(" ", ", ")})`) : null),
      h("div", { class: "pose-axes" }, POSE_AXES.map((axis, i) => h("label", { class: "axis" }, axis,
        numberInput(`${id}-${axis}`, { ...p, min: null, max: null, datatype: "decimal" }, pose[i], `${p.label} ${axis}`)))),
      hint, error);
  }
  let input;
  if (p.datatype === "boolean") {
    input = h("input", { id, name: p.name, type: "checkbox", checked: Boolean(value ?? p.default),
      "aria-describedby": `${id}-hint ${id}-error` });
  } else if (p.datatype === "decimal" || p.datatype === "integer") {
    input = numberInput(id, p, value ?? p.default, undefined);
  } else {
    input = h("input", { id, name: p.name, type: "text", value: value ?? p.default ?? "",
      "aria-describedby": `${id}-hint ${id}-error` });
  }
  return h("div", { class: "field", dataset: { param: p.name, kind: p.datatype } },
    h("label", { for: id }, p.label), h("div", { class: "input-unit" }, input, unit), hint, error);
}

function roleField(process, role, step) {
  const o = offer(process.command);
  const fitting = o ? [...(o.role_devices[role.name] || [])]
    : (state.cell ? state.cell.devices.map((d) => d.id) : []);
  const id = `role-${role.name}`;
  const chosen = step && step.bind ? step.bind[role.name] : undefined;
  const hint = `${role.skill}; starts ${role.start}, ends ${role.end}`;
  if (fitting.length === 1 && (!chosen || chosen === fitting[0])) {
    return h("div", { class: "field role", dataset: { role: role.name, fixed: fitting[0] } },
      h("span", { class: "label", id: `${id}-label` }, role.name),
      h("output", { "aria-labelledby": `${id}-label` }, fitting[0]), h("span", { class: "hint" }, hint));
  }
  const options = [...fitting];
  if (chosen && !options.includes(chosen)) options.push(chosen);
  const select = h("select", { id, name: role.name, "aria-describedby": `${id}-hint` },
    options.length ? null : h("option", { value: "" }, "no device fits"),
    options.map((d) => h("option", { value: d, selected: d === (chosen || options[0]) }, d)));
  return h("div", { class: "field role", dataset: { role: role.name } },
    h("label", { for: id }, role.name), select, h("span", { id: `${id}-hint`, class: "hint" }, `${hint}; ${fitting.length} devices fit`));
}

function same(a, b) {
  return JSON.stringify(a) === JSON.stringify(b);
}

function readParam(p, root) {
  const box = root.querySelector(`[data-param="${CSS.escape(p.name)}"]`);
  const source = box.querySelector("select.source");
  if (source && source.value !== ENTERED) {
    const [from, output] = source.value.split(".");
    return { value: { from, output } };
  }
  if (p.datatype === "pose") {
    const inputs = [...box.querySelectorAll("input")];
    if (inputs.every((i) => i.value === "" && !i.validity.badInput)) return { value: undefined };
    if (inputs.some((i) => i.validity.badInput || i.value === "")) {
      return { error: "takes a pose of six numbers [x, y, z, rx, ry, rz]" };
    }
    return { value: inputs.map((i) => Number(i.value)) };
  }
  const input = box.querySelector("input");
  if (p.datatype === "boolean") return { value: input.checked };
  if (p.datatype === "decimal" || p.datatype === "integer") {
    if (input.validity.badInput) return { error: `takes ${p.datatype === "integer" ? "a whole number" : "a number"}` };
    return { value: input.value === "" ? undefined : Number(input.value) };
  }
  return { value: input.value === "" ? undefined : input.value };
}

function setError(root, name, message) {
  const box = root.querySelector(`[data-param="${CSS.escape(name)}"]`);
  if (!box) return false;
  box.querySelector(".field-error").textContent = message;
  box.querySelectorAll("input").forEach((i) => i.setAttribute("aria-invalid", "true"));
  return true;
}

function clearErrors(root) {
  root.querySelectorAll(".field-error").forEach((e) => { e.textContent = ""; });
  root.querySelectorAll("[aria-invalid]").forEach((e) => e.removeAttribute("aria-invalid"));
  $("#dialog-error").textContent = "";
}

/** Build the step from the form; local type errors are shown at their fields. */
function readStep(process, previous, root) {
  const params = {};
  let ok = true;
  for (const p of process.parameters) {
    const { value, error } = readParam(p, root);
    if (error) {
      setError(root, p.name, `parameter '${p.name}' ${error}`);
      ok = false;
    } else if (value !== undefined && !same(value, p.default)) {
      params[p.name] = value;
    }
  }
  const known = new Set(process.parameters.map((p) => p.name));
  for (const [name, value] of Object.entries((previous && previous.params) || {})) {
    if (!known.has(name)) params[name] = value; // kept: the check reports it, a repair may drop it
  }
  const bind = {};
  root.querySelectorAll(".field.role select").forEach((s) => { if (s.value) bind[s.name] = s.value; });
  const named = root.querySelector("#step-name");
  const name = named ? named.value.trim() : (previous && previous.name) || "";
  const on = previous && previous.on ? { on: previous.on } : {}; // its branches stay
  return ok ? { ...(name ? { name } : {}), command: process.command, bind, params, ...on } : null;
}

/** Ask the API to validate the task with this step in its place; show each problem at its field. */
async function refused(step, at, root) {
  const steps = withStep(at.steps, at.place, step);
  const result = await post("/api/task/validate", taskBody({ ...state.task, steps }));
  const row = rowOf(steps, at.place);
  const mine = result.problems.filter((p) => p.row === row);
  let first = null;
  for (const p of mine) {
    const name = p.field.split(".params.")[1];
    if (!(name && setError(root, name, p.message))) {
      $("#dialog-error").textContent = p.message;
    }
    first = first || (name && root.querySelector(`[data-param="${CSS.escape(name)}"] input`));
  }
  if (first) first.focus();
  return mine.length > 0;
}

/** "step 3", or "step 3.2 in the NoPartFound branch of step 3". */
function stepTitle(at, step) {
  const steps = withStep(at.steps, at.place, step);
  const owner = at.place.length > 1 ? ` in the ${at.place[at.place.length - 2]} branch of step ${numberOf(steps, at.place.slice(0, -2))}` : "";
  return `step ${numberOf(steps, at.place)}${owner}`;
}

/**
 * Open the dialog for `command`: a new step at `at.place` of the steps `at.steps` (one past the end of its list),
 * or the step there (`previous`) to edit. Resolves to the step, or null when cancelled.
 */
export function editStep(command, at, previous) {
  const process = state.processes.get(command);
  const dialog = $("#step-dialog");
  const root = $("#step-form");
  if (!process) return Promise.resolve(null);
  $("#dialog-title").textContent = `${previous ? "Edit" : "Add"} ${stepTitle(at, previous || { command })}: ${process.label}`;
  $("#dialog-comment").textContent = process.comment || "";
  $("#dialog-ok").textContent = previous ? "Save step" : "Add step";
  fill($("#dialog-roles"), h("legend", {}, "Devices"), nameField(process, previous),
    process.roles.map((r) => roleField(process, r, previous)));
  const params = process.parameters.map((p) => paramField(p, previous && previous.params ? previous.params[p.name] : undefined, at, root));
  fill($("#dialog-params"), h("legend", {}, "Parameters"), params.length ? params : h("p", { class: "hint" }, "This process has no parameters."));
  clearErrors(root);
  return new Promise((resolve) => {
    const done = (value) => {
      root.removeEventListener("submit", submit);
      $("#dialog-cancel").removeEventListener("click", cancel);
      dialog.removeEventListener("cancel", cancel);
      if (dialog.open) dialog.close();
      resolve(value);
    };
    const cancel = (e) => { e.preventDefault(); done(null); };
    const submit = async (e) => {
      e.preventDefault();
      clearErrors(root);
      const step = readStep(process, previous, root);
      if (!step) return;
      const ok = $("#dialog-ok");
      ok.disabled = true;
      ok.setAttribute("aria-busy", "true");
      try {
        if (!(await refused(step, at, root))) done(step);
      } catch (err) {
        $("#dialog-error").textContent = err.message;
      } finally {
        ok.disabled = false;
        ok.removeAttribute("aria-busy");
      }
    };
    root.addEventListener("submit", submit);
    $("#dialog-cancel").addEventListener("click", cancel);
    dialog.addEventListener("cancel", cancel);
    dialog.showModal();
    const first = root.querySelector("select, input");
    if (first) first.focus();
  });
}
