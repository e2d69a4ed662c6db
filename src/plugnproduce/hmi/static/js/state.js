// What the page knows: the cell, the offered commands, the processes, the task being edited, the run.

import { numberOf, placeKey, rowsOf } from "./places.js";

const TASK_KEY = "pnp-task";

export const state = {
  cell: null, // {name, devices: [...]}
  commands: null, // {offered: [{command, label, bindings}], not_offered: [{command, label, reasons}]}; null until loaded
  pluggable: false,
  catalogue: [],
  processes: new Map(), // command -> process (roles, parameters)
  // steps: the task's steps, each with its branches (`on: {OUTCOME: [steps]}`); loops: [{first, last, until, while, max}]
  // (indices of the task's steps, not of its branches' steps)
  task: { name: "task", description: "", repeat: 1, steps: [], loops: [] },
  check: null, // the last check (with repairs) of the task as it is
  run: null, // {run, status, step, states, faults, lines}
  generated: [], // charts of the last generation
  reports: {}, // device -> the quantities it reports with its state (teach-in)
};

const bus = new EventTarget();

/** Tell every part of the page that something changed ("cell", "task", "check", "run", "generated"). */
export function changed(what, detail) {
  bus.dispatchEvent(new CustomEvent(what, { detail }));
}

export function on(what, fn) {
  bus.addEventListener(what, (e) => fn(e.detail));
}

export function offer(command) {
  return state.commands ? state.commands.offered.find((o) => o.command === command) : undefined;
}

/**
 * The outcomes a branch on a step of `command` (or a loop over it) may name, as the server describes them:
 * [{outcome, label, covers}], those the process may end with, then the more general ones they fall under.
 */
export function outcomeChoices(command) {
  const p = state.processes.get(command);
  return (p && p.outcome_choices) || [];
}

/** An outcome choice in words: "BinEmpty", or "NoPartFound (reported as BinEmpty)" for a more general one. */
export function outcomeText(choice) {
  const same = choice.covers.length === 1 && choice.covers[0] === choice.outcome;
  return same ? choice.outcome : `${choice.outcome} (reported as ${choice.covers.join(" or ")})`;
}

export function saveTask() {
  try {
    localStorage.setItem(TASK_KEY, JSON.stringify(state.task));
  } catch {
    /* storage full or disabled: the task lives in the page only */
  }
}

export function loadTask() {
  try {
    const saved = JSON.parse(localStorage.getItem(TASK_KEY) || "null");
    if (saved && Array.isArray(saved.steps)) state.task = { ...state.task, loops: [], ...saved };
  } catch {
    /* a damaged saved task is dropped */
  }
}

/** A step as the API takes it; a branch on an outcome holds its steps (`on: {NoPartFound: [...]}`). */
function stepBody(s) {
  const on = Object.entries(s.on || {}).filter(([, steps]) => steps.length);
  return { ...(s.name ? { name: s.name } : {}), command: s.command, bind: s.bind || {}, params: s.params || {},
    ...(on.length ? { on: Object.fromEntries(on.map(([outcome, steps]) => [outcome, steps.map(stepBody)])) } : {}) };
}

/** The loop whose body holds editor row `row`, if any. */
export function loopOf(row, task = state.task) {
  return (task.loops || []).find((l) => l.first <= row && row <= l.last);
}

/** The task as the API takes it (and the task file writes it): a loop is one item holding its body. */
export function taskBody(task = state.task) {
  const steps = [];
  task.steps.forEach((s, row) => {
    const loop = loopOf(row, task);
    if (!loop) steps.push(stepBody(s));
    else if (row === loop.first) {
      steps.push({ loop: { ...(loop.until ? { until: loop.until } : {}), ...(loop.while ? { while: loop.while } : {}),
        ...(loop.max ? { max: loop.max } : {}),
        steps: task.steps.slice(loop.first, loop.last + 1).map(stepBody) } });
    }
  });
  return { name: task.name || "task", description: task.description || "", repeat: Number(task.repeat) || 1, steps };
}

/** A task from the API as the editor holds it: one row per step, each loop as the rows it spans. */
export function editorTask(body) {
  if (rowsOf(body.steps).some((r) => r.depth > 0 && r.step.loop)) {
    throw new Error("This task has a loop inside a branch: the editor builds loops of the task's steps only; "
      + "edit that task file by hand.");
  }
  if (body.steps.some((item) => item.loop && rowsOf(item.loop.steps || []).some((r) => r.step.loop))) {
    throw new Error("This task has a loop inside a loop: the editor builds loops of the task's steps only; "
      + "edit that task file by hand.");
  }
  const steps = [];
  const loops = [];
  for (const item of body.steps) {
    if (!item.loop) {
      steps.push(item);
      continue;
    }
    const { until, max, steps: inner } = item.loop;
    loops.push({ first: steps.length, last: steps.length + inner.length - 1, until: until || null,
      while: item.loop.while || null, max: max || null });
    steps.push(...inner);
  }
  return { name: body.name, description: body.description || "", repeat: body.repeat || 1, steps, loops };
}

/**
 * Where each step position of a run lies in the editor: {row, top, place, number, step, loop, iteration,
 * branch}. Positions number the steps as the server does: a step, then its branches' steps; a loop's body
 * twice (iteration 1, then 2 for "2 and later"). `top` is the index of the task's step the position is, or
 * lies in a branch of; `branch` is the innermost branch holding it ({place of its step, outcome}) or null.
 */
export function stepPositions(task = state.task) {
  const rows = new Map(rowsOf(task.steps).map((r) => [placeKey(r.place), r.row]));
  const out = [null];
  const walk = (step, place, at) => {
    out.push({ ...at, row: rows.get(placeKey(place)), place, number: numberOf(task.steps, place), step });
    for (const [outcome, inner] of Object.entries(step.on || {})) {
      inner.forEach((s, j) => walk(s, [...place, outcome, j], { ...at, branch: { place, outcome } }));
    }
  };
  const add = (top, loop, iteration) => walk(task.steps[top], [top], { top, loop, iteration, branch: null });
  task.steps.forEach((_, top) => {
    const loop = loopOf(top, task);
    if (!loop) add(top, null, 1);
    else if (top === loop.last) {
      for (const iteration of [1, 2]) {
        for (let r = loop.first; r <= loop.last; r++) add(r, loop, iteration);
      }
    }
  });
  return out;
}
