// The task editor: add, edit, remove and reorder steps; loops around steps; check with problems at
// their steps; ranked repairs applied with one click; why a step is (not) plausible; YAML in and out.

import { api, post } from "./api.js";
import { explanationView } from "./derivation.js";
import { editStep } from "./dialog.js";
import { $, announce, fill, h, showValue } from "./dom.js";
import { editLoop, loopText } from "./loops.js";
import { changed, editorTask, loopOf, offer, saveTask, state, taskBody } from "./state.js";

let checkTimer = null;
let checkSeq = 0;

function label(command) {
  const p = state.processes.get(command);
  return p ? p.label : command;
}

function paramSummary(step) {
  const process = state.processes.get(step.command);
  const units = new Map(process ? process.parameters.map((p) => [p.name, p.unit]) : []);
  const parts = Object.entries(step.params || {}).map(([k, v]) => (v && v.from
    ? `${k.replace(/_/g, " ")} ← ${v.output.replace(/_/g, " ")} of ${v.from}`
    : `${k.replace(/_/g, " ")} ${showValue(v, units.get(k))}`));
  const binds = Object.entries(step.bind || {}).map(([role, dev]) => `${role} → ${dev}`);
  return [...binds, ...parts].join(" · ") || "defaults";
}

/** Change the task, remember it, re-render and re-check. */
export function setTask(task, message) {
  state.task = task;
  state.check = null; // about the task as it was; the check below replaces it
  saveTask();
  renderTask();
  changed("task", task);
  scheduleCheck();
  if (message) announce(message);
}

function setSteps(steps, message, focusRow, focusSelector, loops = state.task.loops || []) {
  setTask({ ...state.task, steps, loops }, message);
  if (focusRow !== undefined) {
    const li = $(`#steps li[data-row="${focusRow}"]`);
    const target = li && (li.querySelector(focusSelector) || li.querySelector("button:not([disabled])"));
    if (target) target.focus();
  }
}

/** Open the dialog for a new step at the end of the task. */
export async function addStep(command) {
  const row = state.task.steps.length;
  const step = await editStep(command, row);
  if (step) setSteps([...state.task.steps, step], `Step ${row + 1} (${label(command)}) added.`, row, ".edit");
}

async function edit(row) {
  const old = state.task.steps[row];
  const step = await editStep(old.command, row, old);
  if (step) {
    const steps = [...state.task.steps];
    steps[row] = step;
    setSteps(steps, `Step ${row + 1} saved.`, row, ".edit");
  }
}

function move(row, delta) {
  const to = row + delta;
  const steps = [...state.task.steps];
  if (to < 0 || to >= steps.length) return;
  [steps[row], steps[to]] = [steps[to], steps[row]];
  setSteps(steps, `Step ${row + 1} moved to position ${to + 1}.`, to, delta < 0 ? ".up" : ".down");
}

function remove(row) {
  const steps = state.task.steps.filter((_, i) => i !== row);
  const loops = (state.task.loops || [])
    .map((l) => ({ ...l, first: l.first > row ? l.first - 1 : l.first, last: l.last >= row ? l.last - 1 : l.last }))
    .filter((l) => l.first <= l.last);
  setSteps(steps, `Step ${row + 1} (${label(state.task.steps[row].command)}) removed.`, Math.min(row, steps.length - 1),
    ".edit", loops);
}

/** Open the loop dialog: a new loop around steps, or the loop at `index` to change. */
async function loopDialog(index) {
  const loops = [...(state.task.loops || [])];
  const old = index === undefined ? null : loops[index];
  const loop = await editLoop(old);
  if (!loop) return;
  if (old) loops[index] = loop;
  else loops.push(loop);
  loops.sort((a, b) => a.first - b.first);
  setSteps(state.task.steps, `${loopText(loop)} ${old ? "saved" : "added"}.`, undefined, undefined, loops);
}

function removeLoop(loop) {
  setSteps(state.task.steps, `${loopText(loop)} removed; its steps run once.`, loop.first, ".edit",
    state.task.loops.filter((l) => l !== loop));
}

function loopHead(loop) {
  const index = state.task.loops.indexOf(loop);
  const text = loopText(loop);
  return h("li", { class: "loop-head", dataset: { first: loop.first, last: loop.last } },
    h("span", { class: "loop-text" }, text),
    h("span", { class: "step-actions" },
      h("button", { type: "button", class: "edit-loop quiet", "aria-label": `Edit ${text}`, onclick: () => loopDialog(index) },
        "Edit loop"),
      h("button", { type: "button", class: "remove-loop quiet danger", "aria-label": `Remove ${text}`,
        onclick: () => removeLoop(loop) }, "Remove loop")));
}

function stepItem(step, row, count) {
  const n = row + 1;
  const name = `step ${n} (${label(step.command)})`;
  const offered = !state.commands || offer(step.command);
  const li = h("li", { class: loopOf(row) ? "step in-loop" : "step", dataset: { row, command: step.command } },
    h("div", { class: "step-head" },
      h("span", { class: "step-no", "aria-hidden": "true" }, String(n)),
      h("div", { class: "step-main" },
        h("span", { class: "step-cmd" }, label(step.command), " ", h("code", {}, step.command),
          step.name ? h("span", { class: "badge step-name" }, step.name) : null,
          offered ? null : h("span", { class: "badge warn" }, "not offered")),
        h("span", { class: "step-detail" }, paramSummary(step))),
      h("span", { class: "step-actions" },
        h("button", { type: "button", class: "edit quiet", "aria-label": `Edit ${name}`, onclick: () => edit(row) }, "Edit"),
        h("button", { type: "button", class: "up quiet", "aria-label": `Move ${name} up`, disabled: row === 0,
          onclick: () => move(row, -1) }, "↑"),
        h("button", { type: "button", class: "down quiet", "aria-label": `Move ${name} down`, disabled: row === count - 1,
          onclick: () => move(row, 1) }, "↓"),
        h("button", { type: "button", class: "remove quiet danger", "aria-label": `Remove ${name}`,
          onclick: () => remove(row) }, "Remove"))),
    h("ul", { class: "problems", "aria-label": `Problems of ${name}` }));
  li.addEventListener("keydown", (e) => {
    if (e.altKey && (e.key === "ArrowUp" || e.key === "ArrowDown")) {
      e.preventDefault();
      move(row, e.key === "ArrowUp" ? -1 : 1);
    }
  });
  return li;
}

/** Show the task as it is. */
export function renderTask() {
  const t = state.task;
  if (document.activeElement !== $("#task-name")) $("#task-name").value = t.name;
  if (document.activeElement !== $("#task-repeat")) $("#task-repeat").value = t.repeat;
  if (document.activeElement !== $("#task-description")) $("#task-description").value = t.description || "";
  fill($("#steps"), t.steps.flatMap((s, i) => {
    const loop = (t.loops || []).find((l) => l.first === i);
    return [loop ? loopHead(loop) : null, stepItem(s, i, t.steps.length)];
  }));
  $("#add-loop").disabled = t.steps.length === 0;
  $("#steps-empty").hidden = t.steps.length > 0;
  renderCheck();
}

async function why(problem, box, button) {
  const open = button.getAttribute("aria-expanded") === "true";
  button.setAttribute("aria-expanded", String(!open));
  box.hidden = open;
  if (open) return;
  try {
    const ex = await post(`/api/task/explain?step=${problem.step}`, taskBody());
    fill(box, explanationView(ex));
  } catch (err) {
    fill(box, h("p", { class: "error" }, err.message));
  }
}

function problemItem(p, i) {
  const id = `why-step-${p.step}-${i}`;
  const box = h("div", { id, class: "why", hidden: true });
  const button = h("button", { type: "button", class: "quiet", "aria-expanded": "false", "aria-controls": id,
    onclick: () => why(p, box, button) }, "Why?");
  const round = p.round > 1 ? ` (round ${p.round})` : "";
  return h("li", { class: "problem", dataset: { kind: p.kind } }, h("span", {}, (p.plain || p.text) + round), " ", button, box);
}

function applyRepair(repair) {
  setTask({ ...state.task, ...editorTask(repair.task) },
    `Repair ${repair.rank} applied: ${repair.edits.map((e) => e.text).join("; ")}.`);
  $("#check").focus();
}

function repairItem(r) {
  const added = r.added_devices.length ? h("p", { class: "hint" }, `Needs ${r.added_devices.join(", ")} plugged in.`) : null;
  return h("li", { class: "repair", dataset: { rank: r.rank } },
    h("div", { class: "repair-text" },
      h("ul", { class: "edits" }, r.edits.map((e) => h("li", {}, e.text))),
      h("span", { class: "cost" }, `cost ${r.cost}`), added,
      (r.side_effects || []).map((e) => h("p", { class: "side-effect", dataset: { kind: e.kind } }, `Side effect: ${e.text}`))),
    h("button", { type: "button", class: "apply primary", "aria-label": `Apply repair ${r.rank}: ${r.edits.map((e) => e.text).join("; ")}`,
      onclick: () => applyRepair(r) }, "Apply"));
}

/** Show the last check: the verdict, each problem at its step, and the repairs. */
export function renderCheck() {
  const c = state.check;
  const verdict = $("#verdict");
  document.querySelectorAll("#steps .step").forEach((li) => li.classList.remove("has-problem"));
  if (!c) {
    fill(verdict);
    $("#repairs").hidden = true;
    return;
  }
  if (c.error) {
    fill(verdict, h("p", { class: "error" }, c.error));
    $("#repairs").hidden = true;
    return;
  }
  const unplaced = [];
  c.problems.forEach((p, i) => {
    const li = p.row !== undefined ? $(`#steps li[data-row="${p.row}"]`) : null;
    if (li) {
      li.classList.add("has-problem");
      li.querySelector(".problems").append(problemItem(p, i));
    } else unplaced.push(p);
  });
  fill(verdict, c.plausible
    ? h("p", { class: "ok" }, `Plausible: every step finds its devices in the states it starts from.`)
    : h("p", { class: "bad" }, `Not plausible: ${c.problems.length} problem${c.problems.length === 1 ? "" : "s"}`,
      c.repairs.length ? `; ${c.repairs.length} repair${c.repairs.length === 1 ? "" : "s"} below.` : "; no repair found."),
  unplaced.map((p) => h("p", { class: "error" }, p.plain || p.text)));
  $("#repairs").hidden = c.plausible || c.repairs.length === 0;
  fill($("#repair-list"), c.repairs.map(repairItem));
}

/** Check the task now (with repairs when it is not plausible). */
export async function check() {
  clearTimeout(checkTimer);
  const seq = ++checkSeq;
  if (state.task.steps.length === 0) {
    state.check = null;
    renderCheck();
    return;
  }
  try {
    const result = await post("/api/task/repair", taskBody());
    if (seq === checkSeq) state.check = result;
  } catch (err) {
    if (seq === checkSeq) state.check = { error: err.message };
  }
  if (seq === checkSeq) {
    renderTask();
    changed("check", state.check);
  }
}

/** Check again shortly (after an edit, or when the cell changed). */
export function scheduleCheck() {
  clearTimeout(checkTimer);
  checkTimer = setTimeout(check, 250);
}

async function exportYaml() {
  try {
    const text = await api("POST", "/api/task/export", taskBody());
    const url = URL.createObjectURL(new Blob([text], { type: "application/yaml" }));
    const a = h("a", { href: url, download: `${state.task.name || "task"}.yaml` });
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  } catch (err) {
    state.check = { error: err.message };
    renderCheck();
  }
}

async function importYaml(file) {
  try {
    const text = await file.text();
    const task = await api("POST", `/api/task/import?filename=${encodeURIComponent(file.name)}`, text,
      { raw: true, contentType: "application/yaml" });
    const loaded = editorTask(task);
    setTask(loaded, `Task ${task.name} imported with ${loaded.steps.length} steps.`);
  } catch (err) {
    state.check = { error: err.message };
    renderCheck();
  }
}

export function initEditor() {
  $("#task-name").addEventListener("change", (e) => setTask({ ...state.task, name: e.target.value.trim() || "task" }));
  $("#task-repeat").addEventListener("change", (e) => {
    const n = Math.min(1000, Math.max(1, Math.round(Number(e.target.value)) || 1));
    setTask({ ...state.task, repeat: n });
  });
  $("#task-description").addEventListener("change", (e) => setTask({ ...state.task, description: e.target.value }));
  $("#check").addEventListener("click", check);
  $("#export").addEventListener("click", exportYaml);
  $("#import-button").addEventListener("click", () => $("#import").click());
  $("#import").addEventListener("change", (e) => {
    if (e.target.files[0]) importYaml(e.target.files[0]);
    e.target.value = "";
  });
  $("#add-loop").addEventListener("click", () => loopDialog());
  $("#clear").addEventListener("click", () => setTask({ name: "task", description: "", repeat: 1, steps: [], loops: [] },
    "Task cleared."));
}
