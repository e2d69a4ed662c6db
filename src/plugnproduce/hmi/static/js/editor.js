// The task editor: add, edit, remove and reorder steps; loops around steps, branches on a step's outcome;
// check with problems at their steps; ranked repairs applied with one click; why a step is (not) plausible; YAML in and out.

import { api, post } from "./api.js";
import { explanationView } from "./derivation.js";
import { editStep } from "./dialog.js";
import { branchText, editBranch } from "./branches.js";
import { $, announce, fill, h } from "./dom.js";
import { editLoop, loopText } from "./loops.js";
import { listAt, numberOf, placeKey, stepAt, withList, withStep } from "./places.js";
import { changed, editorTask, saveTask, state, taskBody } from "./state.js";
import { label } from "./steptext.js";
import { taskItems } from "./tasklist.js";

let checkTimer = null;
let checkSeq = 0;
let checksInFlight = 0;

/** Count a check sent (+1) or answered (-1): the verdict is busy while any is in flight. */
function checking(delta) {
  checksInFlight += delta;
  $("#verdict").setAttribute("aria-busy", String(checksInFlight > 0));
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

function setSteps(steps, message, focus, focusSelector, loops = state.task.loops || []) {
  setTask({ ...state.task, steps, loops }, message);
  if (focus !== undefined) {
    const li = $(`#steps li.step[data-place="${placeKey(focus)}"]`);
    const target = li && (li.querySelector(`${focusSelector}:not([disabled])`) || li.querySelector("button:not([disabled])"));
    if (target) target.focus();
  }
}

/** Open the dialog for a new step at the end of the task. */
export async function addStep(command) {
  const place = [state.task.steps.length];
  const step = await editStep(command, { steps: state.task.steps, place });
  if (step) setSteps([...state.task.steps, step], `Step ${place[0] + 1} (${label(command)}) added.`, place, ".edit");
}

function nameOf(place) {
  return `Step ${numberOf(state.task.steps, place)} (${label(stepAt(state.task.steps, place).command)})`;
}

async function edit(place) {
  const old = stepAt(state.task.steps, place);
  const step = await editStep(old.command, { steps: state.task.steps, place }, old);
  if (step) setSteps(withStep(state.task.steps, place, step), `${nameOf(place)} saved.`, place, ".edit");
}

function move(place, delta) {
  const prefix = place.slice(0, -1);
  const row = place[place.length - 1];
  const to = row + delta;
  if (to < 0 || to >= listAt(state.task.steps, prefix).length) return;
  const steps = withList(state.task.steps, prefix, (list) => {
    const copy = [...list];
    [copy[row], copy[to]] = [copy[to], copy[row]];
    return copy;
  });
  setSteps(steps, `${nameOf(place)} moved to position ${numberOf(steps, [...prefix, to])}.`, [...prefix, to],
    delta < 0 ? ".up" : ".down");
}

/** The loops once the task's step `row` is gone (a loop left with no step goes too). */
function loopsWithout(row) {
  return (state.task.loops || [])
    .map((l) => ({ ...l, first: l.first > row ? l.first - 1 : l.first, last: l.last >= row ? l.last - 1 : l.last }))
    .filter((l) => l.first <= l.last);
}

function remove(place) {
  const steps = withStep(state.task.steps, place, null);
  const loops = place.length === 1 ? loopsWithout(place[0]) : state.task.loops;
  const left = listAt(steps, place.slice(0, -1)).length;
  const focus = left ? [...place.slice(0, -1), Math.min(place[place.length - 1], left - 1)] : place.slice(0, -2);
  setSteps(steps, `${nameOf(place)} removed.`, focus.length ? focus : undefined, ".edit", loops);
}

/** Open the branch dialog: a new branch of the step at `place`, or its branch on `old` to change. */
async function branchDialog(place, old) {
  const branch = await editBranch(place, old);
  if (!branch) return;
  const without = old ? withList(state.task.steps, [...place, old], () => []) : state.task.steps;
  const steps = withList(without, [...place, branch.outcome], () => branch.steps);
  setSteps(steps, `${branchText(steps, place, branch.outcome)}: ${branch.steps.length} step${branch.steps.length === 1 ? "" : "s"} ${old ? "saved" : "added"}.`,
    place, ".add-branch");
}

function removeBranch(place, outcome) {
  const text = branchText(state.task.steps, place, outcome);
  setSteps(withList(state.task.steps, [...place, outcome], () => []), `Branch removed: ${text}.`, place, ".edit");
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
  setSteps(state.task.steps, `${loopText(loop)} removed; its steps run once.`, [loop.first], ".edit",
    state.task.loops.filter((l) => l !== loop));
}

const ACTIONS = { edit, move, remove, branch: branchDialog, removeBranch, loop: loopDialog, removeLoop };

/** Redraw `box`; a control in it that had the keyboard's focus has it again in the redrawn box (found by its
 * label), so a check's answer arriving while someone works from the keyboard does not throw them out. */
function keepingFocus(box, redraw) {
  const active = document.activeElement;
  const label = active && box.contains(active) ? active.getAttribute("aria-label") : null;
  redraw();
  if (label === null || box.contains(document.activeElement)) return;
  const again = [...box.querySelectorAll("[aria-label]")].find((el) => el.getAttribute("aria-label") === label);
  if (again) again.focus();
}

/** Show the task as it is. */
export function renderTask() {
  const t = state.task;
  if (document.activeElement !== $("#task-name")) $("#task-name").value = t.name;
  if (document.activeElement !== $("#task-repeat")) $("#task-repeat").value = t.repeat;
  if (document.activeElement !== $("#task-description")) $("#task-description").value = t.description || "";
  keepingFocus($("#steps"), () => fill($("#steps"), taskItems(t, ACTIONS)));
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

/** A finding's text without the path it starts with (shown apart): "branch X at step 1: step 2 …" → "step 2 …". */
function withoutPath(text, path) {
  let rest = text;
  for (const part of (path || "").split(", ")) {
    const sep = [": ", ", "].find((x) => part && rest.startsWith(part + x));
    if (sep) rest = rest.slice(part.length + sep.length);
  }
  return rest;
}

function problemItem(p, i) {
  const id = `why-step-${p.step}-${i}`;
  const box = h("div", { id, class: "why", hidden: true });
  const button = h("button", { type: "button", class: "quiet", "aria-expanded": "false", "aria-controls": id,
    onclick: () => why(p, box, button) }, "Why?");
  const round = p.round > 1 && !p.path ? ` (round ${p.round})` : "";
  return h("li", { class: "problem", dataset: { kind: p.kind } },
    p.path ? h("span", { class: "badge path" }, p.path) : null, " ",
    h("span", {}, withoutPath(p.plain || p.text, p.path) + round), " ", button, box);
}

function applyRepair(repair) {
  setTask({ ...state.task, ...editorTask(repair.task) },
    `Repair ${repair.rank} applied: ${repair.edits.map((e) => e.text).join("; ")}.`);
  $("#check").focus();
}

/** How many loops and branches a task's items hold. */
function flowCount(items) {
  return items.reduce((n, item) => (item.loop ? n + 1 + flowCount(item.loop.steps)
    : n + Object.values(item.on || {}).reduce((m, inner) => m + 1 + flowCount(inner), 0)), 0);
}

function repairItem(r) {
  const added = r.added_devices.length ? h("p", { class: "hint" }, `Needs ${r.added_devices.join(", ")} plugged in.`) : null;
  // a repair that writes the loops and branches out step by step (the server says so) is not the operator's task
  const unrolls = r.unrolls ?? flowCount(r.task.steps) < flowCount(taskBody().steps);
  return h("li", { class: "repair", dataset: { rank: r.rank } },
    h("div", { class: "repair-text" },
      h("ul", { class: "edits" }, r.edits.map((e) => h("li", {}, e.text))),
      h("span", { class: "cost" }, `cost ${r.cost}`), added,
      (r.side_effects || []).map((e) => h("p", { class: "side-effect", dataset: { kind: e.kind } }, `Side effect: ${e.text}`)),
      unrolls ? h("p", { class: "hint unrolls" }, r.note ? `${r.note}. Make these changes through the dialogs.`
        : "Applying it here would write the loops and branches out step by step: make these changes through the dialogs.") : null),
    h("button", { type: "button", class: "apply primary", "aria-label": `Apply repair ${r.rank}: ${r.edits.map((e) => e.text).join("; ")}`,
      disabled: unrolls, onclick: () => applyRepair(r) }, "Apply"));
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
  checking(+1);
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
  checking(-1);
}

/** Check again shortly (after an edit, or when the cell changed). */
export function scheduleCheck() {
  clearTimeout(checkTimer);
  ++checkSeq; // a check still in flight is about the task as it was: its answer is not shown
  checkTimer = setTimeout(check, 250);
}

/** Show an error in the verdict's place, until the next edit or check: no earlier check's answer replaces it. */
function showError(message) {
  clearTimeout(checkTimer);
  ++checkSeq;
  state.check = { error: message };
  renderCheck();
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
    showError(err.message);
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
    showError(err.message);
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
