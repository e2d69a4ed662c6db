// Runs: start and stop, each device's state and the current step live, a loop's iteration, the branch
// taken after each step with branches, each value as it flows from the step that produced it to the step that used it, the journal, the fault report.

import { get, post } from "./api.js";
import { renderDeviceState } from "./cell.js";
import { $, announce, fill, h, showValue } from "./dom.js";
import { loopText } from "./loops.js";
import { placeKey } from "./places.js";
import { initResume, renderResume } from "./resume.js";
import { state, stepPositions, taskBody } from "./state.js";

/** Where step position `n` of the run lies in the editor's task: {row, loop, iteration}. */
function where(n) {
  const positions = stepPositions();
  const count = positions.length - 1;
  return count > 0 && n >= 1 ? positions[((n - 1) % count) + 1] : null;
}

/** Each loop's iteration as of journal record `seq`: a new one starts whenever its first step is entered. */
function iterations(run, seq = Infinity) {
  const counts = new Map();
  for (const v of run.visited || []) {
    const at = where(v.step);
    if (v.seq < seq && at && at.loop && at.top === at.loop.first && !at.branch) counts.set(at.loop, (counts.get(at.loop) || 0) + 1);
  }
  return counts;
}

function stepName(n) {
  const at = where(n);
  return at ? `step ${at.number} (${at.step.name || at.step.command})` : `step ${n}`;
}

function valueItem(record, iteration) {
  const produced = "produced" in record;
  const value = showValue(produced ? record.produced : record.used);
  const text = produced
    ? `${record.value} = ${value}, produced by ${stepName(record.step)} on ${record.device}`
    : `${record.value} = ${value}, used by ${stepName(record.step)} as ${record.parameter} on ${record.device}`;
  return h("li", { class: produced ? "produced" : "used", dataset: { value: record.value, iteration: iteration || "" } },
    iteration ? h("span", { class: "badge" }, `iteration ${iteration}`) : null, " ", text);
}

/** A journal record of the branch a run took after a step with branches (or that it took none). */
function branchItem(record, run) {
  const at = where(record.step);
  const next = where(record.next);
  if (!at) return null;
  const iteration = at.loop ? iterations(run, record.seq).get(at.loop) : null;
  const name = (p) => `step ${p.number} (${p.step.name || p.step.command})`;
  const taken = record.branch ? `the ${record.branch} branch taken` : "no branch taken";
  const text = `${name(at)} ended with ${record.outcome}: ${taken}${next ? `, ${name(next)} next` : ""}`;
  return h("li", { class: record.branch ? "branch-taken" : "no-branch",
    dataset: { outcome: record.outcome, branch: record.branch || "", place: placeKey(at.place), iteration: iteration || "" } },
  iteration ? h("span", { class: "badge" }, `iteration ${iteration}`) : null, " ", text);
}

function renderFlow(run) {
  const counts = iterations(run);
  fill($("#run-loops"), [...counts].map(([loop, n]) => h("li", { dataset: { first: loop.first, iteration: n } },
    `${loopText(loop)}: iteration ${n}`)));
  $("#run-loops").hidden = counts.size === 0;
  const items = (run.values || []).map((record) => {
    const at = where(record.step);
    return valueItem(record, at && at.loop ? iterations(run, record.seq).get(at.loop) : null);
  });
  fill($("#run-values"), items);
  $("#run-values-box").hidden = items.length === 0;
  const taken = (run.branches || []).map((record) => branchItem(record, run)).filter(Boolean);
  fill($("#run-branches"), taken);
  $("#run-branches-box").hidden = taken.length === 0;
}

function statusText(run) {
  const step = run.step ? `step ${run.step.step} of ${run.steps}: ${run.step.command}` : "starting";
  // the speed factor the run's simulated devices work at, as its journal's start record says (none: real devices)
  const on = run.speed == null ? "" : ` on simulated devices at speed ${run.speed}`;
  switch (run.status) {
    case "running": return `Run ${run.run} of task ${run.task} is running${on} (${step}).`;
    case "succeeded": return `Run ${run.run} of task ${run.task} succeeded${on}.`;
    case "stopped": return `Run ${run.run} of task ${run.task} was stopped${on}.`;
    default: return `Run ${run.run} of task ${run.task} ${run.status}${on}.`;
  }
}

/** Mark the step running now, and the head of each branch it lies in (the branch the run has taken). */
function markCurrentStep(run) {
  document.querySelectorAll("#steps .step, #steps .branch-head").forEach((li) => {
    li.classList.remove("running");
    li.removeAttribute("aria-current");
  });
  const at = run && run.status === "running" && run.step ? where(run.step.step) : null;
  if (!at) return;
  const li = $(`#steps li[data-row="${at.row}"]`);
  if (li) {
    li.classList.add("running");
    li.setAttribute("aria-current", "step");
  }
  for (let k = 1; k < at.place.length; k += 2) {
    const head = $(`#steps .branch-head[data-place="${placeKey(at.place.slice(0, k))}"][data-outcome="${CSS.escape(at.place[k])}"]`);
    if (head) head.classList.add("running");
  }
}

function faultReport(run) {
  if (run.status !== "failed") return null;
  const fault = run.faults.find((f) => f.first !== false) || null; // the first fault is the cause
  const where = fault && fault.step ? `step ${fault.step}` : "";
  return [
    h("h3", {}, "Fault report"),
    h("p", { class: "fault-message" }, fault ? `${fault.fault}: ${fault.message}` : (run.end && run.end.reason) || "the run failed"),
    h("dl", { class: "facts" },
      fault && fault.device ? [h("dt", {}, "Device"), h("dd", {}, fault.device)] : null,
      where ? [h("dt", {}, "Step"), h("dd", {}, `${where}${run.step ? ` (${run.step.command})` : ""}`)] : null,
      h("dt", {}, "Run"), h("dd", {}, run.run)),
    h("p", {}, "Every device was left in the state it had reached:"),
    h("ul", { class: "fault-states" }, Object.entries(run.states).map(([d, s]) => h("li", {}, `${d}: ${s}`))),
  ];
}

/** Why the task being edited cannot be started now ("" when it can): it must be checked and plausible. */
function startBlocked() {
  if (state.task.steps.length === 0) return "Add steps to the task to run it.";
  const c = state.check;
  if (!c) return "Checking the task…";
  if (c.error) return `The task cannot be checked: ${c.error}`;
  if (!c.plausible) return "The task is not plausible: repair it to run it.";
  return "";
}

/** Enable "Start run" only for a checked, plausible task while no run is running; say why it is disabled. */
export function renderStart() {
  const running = Boolean(state.run && state.run.status === "running");
  const why = running ? "" : startBlocked();
  $("#run-start").disabled = running || Boolean(why);
  $("#run-start-why").textContent = why;
}

/** Show a run as its journal tells it. */
export function renderRun() {
  const run = state.run;
  const running = Boolean(run && run.status === "running");
  renderStart();
  $("#run-stop").disabled = !running;
  renderResume(run);
  if (!run) return;
  const status = $("#run-status");
  status.textContent = statusText(run);
  status.dataset.status = run.status;
  // the current step only while running: a finished run's last step is in its status, journal and fault report
  $("#run-step").textContent = running && run.step
    ? `Current step: ${run.step.step} of ${run.steps}, ${run.step.command}` : "";
  const table = $("#run-states");
  table.hidden = Object.keys(run.states).length === 0;
  const used = new Set(Object.values((run.step && run.step.bindings) || {}));
  fill(table.querySelector("tbody"), Object.entries(run.states).map(([d, s]) =>
    h("tr", { class: used.has(d) && running ? "busy" : "", dataset: { device: d } },
      h("th", { scope: "row" }, d), h("td", {}, h("span", { class: "badge" }, s)))));
  renderFlow(run);
  fill($("#journal"), run.lines.map((line) => h("li", {}, line)));
  const link = $("#journal-link");
  link.href = `/api/runs/${encodeURIComponent(run.run)}/journal?format=jsonl`;
  link.hidden = false;
  const fault = $("#fault");
  const report = faultReport(run);
  fault.hidden = !report;
  fill(fault, report);
  markCurrentStep(run);
}

/** Take in one journal record of a run (from the event stream). */
export function takeRecord({ run: id, record, text }) {
  if (!state.run || state.run.run !== id) {
    state.run = { run: id, task: null, status: "running", steps: null, step: null, states: {}, faults: [], end: null,
      lines: [], seq: 0, visited: [], values: [], branches: [] };
  }
  const run = state.run;
  if (record.seq <= run.seq) return; // already in the run's view
  run.seq = record.seq;
  run.lines.push(text);
  switch (record.kind) {
    case "start":
      Object.assign(run, { task: record.task, cell: record.cell, speed: record.speed ?? null, steps: record.steps,
        states: { ...(record.states || {}) } });
      break;
    case "step":
      run.step = record;
      run.visited.push({ step: record.step, seq: record.seq });
      break;
    case "value": run.values.push(record); break;
    case "branch": run.branches.push(record); break;
    case "state":
      run.states[record.device] = record.state;
      break;
    case "fault": run.faults.push(record); break;
    case "end":
      run.end = record;
      run.status = record.outcome;
      announce(statusText(run));
      break;
    default: break;
  }
  renderRun();
}

/** Take in a device's new state (runs and the live cell both report them). */
export function takeDeviceState({ device, state: s, state_concept: concept }) {
  renderDeviceState(device, s, concept);
}

/** Take the server's answer about a run, unless the event stream has already told more of it. */
function adopt(answer) {
  const seen = state.run;
  if (!(seen && seen.run === answer.run && seen.seq > (answer.seq || 0))) state.run = answer;
}

async function start() {
  const status = $("#run-status");
  try {
    adopt(await post("/api/runs", { task: taskBody() }, { auth: true }));
    announce(statusText(state.run));
    renderRun();
  } catch (err) {
    status.textContent = err.message;
    status.dataset.status = "refused";
    $("#run-step").textContent = ""; // the previous run's step is not this task's
  }
}

async function stop() {
  if (!state.run) return;
  try {
    adopt(await post(`/api/runs/${encodeURIComponent(state.run.run)}/stop`, undefined, { auth: true }));
    renderRun();
  } catch (err) {
    $("#run-status").textContent = err.message;
  }
}

/** Wire the run panel and show the last run, if any. */
export async function initRun() {
  $("#run-start").addEventListener("click", start);
  $("#run-stop").addEventListener("click", stop);
  initResume((answer) => {
    adopt(answer);
    announce(statusText(state.run));
    renderRun();
  }, () => state.run);
  const runs = await get("/api/runs");
  const last = runs.active || (runs.runs.length ? runs.runs[runs.runs.length - 1].run : null);
  if (last) state.run = await get(`/api/runs/${encodeURIComponent(last)}`);
  renderRun();
}
