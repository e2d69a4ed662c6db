// What the page knows: the cell, the offered commands, the processes, the task being edited, the run.

const TASK_KEY = "pnp-task";

export const state = {
  cell: null, // {name, devices: [...]}
  commands: null, // {offered: [{command, label, bindings}], not_offered: [{command, label, reasons}]}; null until loaded
  pluggable: false,
  catalogue: [],
  processes: new Map(), // command -> process (roles, parameters)
  task: { name: "task", description: "", repeat: 1, steps: [], loops: [] }, // loops: [{first, last, until, max}] (rows)
  check: null, // the last check (with repairs) of the task as it is
  run: null, // {run, status, step, states, faults, lines}
  generated: [], // charts of the last generation
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

function stepBody(s) {
  return { ...(s.name ? { name: s.name } : {}), command: s.command, bind: s.bind || {}, params: s.params || {} };
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
      steps.push({ loop: { ...(loop.until ? { until: loop.until } : {}), ...(loop.max ? { max: loop.max } : {}),
        steps: task.steps.slice(loop.first, loop.last + 1).map(stepBody) } });
    }
  });
  return { name: task.name || "task", description: task.description || "", repeat: Number(task.repeat) || 1, steps };
}

/** A task from the API as the editor holds it: one row per step, each loop as the rows it spans. */
export function editorTask(body) {
  const steps = [];
  const loops = [];
  for (const item of body.steps) {
    if (!item.loop) {
      steps.push(item);
      continue;
    }
    const { until, max, steps: inner } = item.loop;
    loops.push({ first: steps.length, last: steps.length + inner.length - 1, until: until || null, max: max || null });
    steps.push(...inner);
  }
  return { name: body.name, description: body.description || "", repeat: body.repeat || 1, steps, loops };
}

/**
 * Where each step position of a run lies in the editor: {row, loop, iteration} (iteration 1, or 2 for
 * "2 and later"). A loop's body counts twice in the positions, as the task's step numbers do.
 */
export function stepPositions(task = state.task) {
  const out = [null];
  task.steps.forEach((_, row) => {
    const loop = loopOf(row, task);
    if (!loop) out.push({ row, loop: null, iteration: 1 });
    else if (row === loop.last) {
      for (const iteration of [1, 2]) {
        for (let r = loop.first; r <= loop.last; r++) out.push({ row: r, loop, iteration });
      }
    }
  });
  return out;
}
