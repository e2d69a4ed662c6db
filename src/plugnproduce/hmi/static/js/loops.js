// The loop dialog: which steps run again and again, until which outcome, at most how often. The
// outcomes offered are those the chosen steps' processes may end with, as the server describes them.

import { $, fill, h } from "./dom.js";
import { rowsOf } from "./places.js";
import { outcomeChoices, outcomeText, state } from "./state.js";

/** A loop in words: "Loop over steps 1–3 until BinEmpty, at most 100 times". */
export function loopText(loop) {
  const steps = loop.first === loop.last ? `step ${loop.first + 1}` : `steps ${loop.first + 1}–${loop.last + 1}`;
  const until = loop.until ? ` until ${loop.until}` : "";
  const goesOn = loop.while ? `${loop.until ? "," : ""} while ${loop.while}` : "";
  const most = loop.max ? `${loop.until || loop.while ? "," : ""} at most ${loop.max} time${loop.max === 1 ? "" : "s"}` : "";
  return `Loop over ${steps}${until}${goesOn}${most}`;
}

function stepOption(row, chosen) {
  const s = state.task.steps[row];
  const p = state.processes.get(s.command);
  return h("option", { value: row, selected: row === chosen }, `${row + 1}: ${p ? p.label : s.command}${s.name ? ` (${s.name})` : ""}`);
}

/** The outcomes a loop over steps first..last (and their branches' steps) may name, each once, in order. */
function outcomesOf(first, last) {
  const out = [];
  for (const { step } of rowsOf(state.task.steps.slice(first, last + 1))) {
    for (const c of outcomeChoices(step.command)) {
      const known = out.find((o) => o.outcome === c.outcome);
      if (!known) out.push({ ...c, covers: [...c.covers] });
      else known.covers.push(...c.covers.filter((x) => !known.covers.includes(x)));
    }
  }
  return out;
}

function fillOutcomes(select, first, last, chosen, none) {
  const outcomes = outcomesOf(first, last);
  fill(select, h("option", { value: "" }, outcomes.length ? none : "no step here ends with an outcome"),
    outcomes.map((c) => h("option", { value: c.outcome, selected: c.outcome === chosen }, outcomeText(c))));
}

function field(id, text, input, hint) {
  return h("div", { class: "field" }, h("label", { for: id }, text), input, hint ? h("span", { class: "hint" }, hint) : null);
}

/** What is wrong with the loop as chosen ("" when nothing), said as the field's fix. */
function refusal(loop, old) {
  if (loop.first > loop.last) return "The last step of the loop must not come before its first.";
  const other = (state.task.loops || []).find((l) => l !== old && l.first <= loop.last && loop.first <= l.last);
  if (other) return `Steps ${other.first + 1}–${other.last + 1} are in a loop already; loops do not nest or overlap.`;
  if (!loop.until && !loop.while && !loop.max) return "A loop needs a way out: an outcome to end on, a maximum, or both.";
  if (loop.max !== null && !(Number.isInteger(loop.max) && loop.max >= 1)) return "The maximum is a whole number, at least 1.";
  if (Number(state.task.repeat) > 1) return "A task with a loop does not repeat: set Repeat to 1 first.";
  return "";
}

/** Open the loop dialog (a new loop, or `old` to change); resolves to the loop, or null when cancelled. */
export function editLoop(old) {
  const dialog = $("#loop-dialog");
  const form = $("#loop-form");
  const rows = state.task.steps.map((_, i) => i);
  const first = h("select", { id: "loop-first", name: "first" }, rows.map((r) => stepOption(r, old ? old.first : 0)));
  const last = h("select", { id: "loop-last", name: "last" },
    rows.map((r) => stepOption(r, old ? old.last : rows.length - 1)));
  const until = h("select", { id: "loop-until", name: "until" });
  const goesOn = h("select", { id: "loop-while", name: "while" });
  const max = h("input", { id: "loop-max", name: "max", type: "number", min: 1, step: 1, inputmode: "numeric",
    value: old && old.max ? old.max : "" });
  const outcomes = () => {
    const [f, l] = [Number(first.value), Number(last.value)];
    fillOutcomes(until, f, l, until.value || (old && old.until), "no outcome: only the maximum");
    fillOutcomes(goesOn, f, l, goesOn.value || (old && old.while), "whatever the steps report");
  };
  outcomes();
  first.addEventListener("change", outcomes);
  last.addEventListener("change", outcomes);
  $("#loop-title").textContent = old ? `Edit loop: ${loopText(old)}` : "Add a loop";
  fill($("#loop-fields"),
    field("loop-first", "First step", first), field("loop-last", "Last step", last),
    field("loop-until", "Until", until, "an outcome the loop's steps may end with"),
    field("loop-while", "While", goesOn, "optional: the loop goes on only while its steps last reported this outcome"),
    field("loop-max", "At most (times)", max, "optional"));
  $("#loop-error").textContent = "";
  return new Promise((resolve) => {
    const done = (value) => {
      form.removeEventListener("submit", submit);
      $("#loop-cancel").removeEventListener("click", cancel);
      dialog.removeEventListener("cancel", cancel);
      if (dialog.open) dialog.close();
      resolve(value);
    };
    const cancel = (e) => { e.preventDefault(); done(null); };
    const submit = (e) => {
      e.preventDefault();
      const loop = { first: Number(first.value), last: Number(last.value), until: until.value || null,
        while: goesOn.value || null, max: max.value === "" ? null : Number(max.value) };
      const why = max.validity.badInput ? "The maximum is a whole number, at least 1." : refusal(loop, old);
      $("#loop-error").textContent = why;
      if (!why) done(loop);
    };
    form.addEventListener("submit", submit);
    $("#loop-cancel").addEventListener("click", cancel);
    dialog.addEventListener("cancel", cancel);
    dialog.showModal();
    first.focus();
  });
}
