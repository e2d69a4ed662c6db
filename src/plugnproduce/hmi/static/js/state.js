// What the page knows: the cell, the offered commands, the processes, the task being edited, the run.

const TASK_KEY = "pnp-task";

export const state = {
  cell: null, // {name, devices: [...]}
  commands: null, // {offered: [{command, label, bindings}], not_offered: [{command, label, reasons}]}; null until loaded
  pluggable: false,
  catalogue: [],
  processes: new Map(), // command -> process (roles, parameters)
  task: { name: "task", description: "", repeat: 1, steps: [] },
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
    if (saved && Array.isArray(saved.steps)) state.task = { ...state.task, ...saved };
  } catch {
    /* a damaged saved task is dropped */
  }
}

/** The task as the API takes it. */
export function taskBody(task = state.task) {
  return {
    name: task.name || "task",
    description: task.description || "",
    repeat: Number(task.repeat) || 1,
    steps: task.steps.map((s) => ({ command: s.command, bind: s.bind || {}, params: s.params || {} })),
  };
}
