// A step in words, as the task list and the branch dialog show it.

import { showValue } from "./dom.js";
import { state } from "./state.js";

/** A process command's label ("localize part"), or the command when the process is unknown. */
export function label(command) {
  const p = state.processes.get(command);
  return p ? p.label : command;
}

/** A step's bindings and values in words ("robot → robot · grip force 45 N"), or "defaults". */
export function paramSummary(step) {
  const process = state.processes.get(step.command);
  const units = new Map(process ? process.parameters.map((p) => [p.name, p.unit]) : []);
  const parts = Object.entries(step.params || {}).map(([k, v]) => (v && v.from
    ? `${k.replace(/_/g, " ")} ← ${v.output.replace(/_/g, " ")} of ${v.from}`
    : `${k.replace(/_/g, " ")} ${showValue(v, units.get(k))}`));
  const binds = Object.entries(step.bind || {}).map(([role, dev]) => `${role} → ${dev}`);
  return [...binds, ...parts].join(" · ") || "defaults";
}
