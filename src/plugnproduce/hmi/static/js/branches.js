// The branch dialog: the steps that run only when a step ends with an outcome. The outcomes offered are
// those the step's process may end with, as the server describes them; the branch's steps are added and
// edited in the same step dialog as the task's steps (devices, parameters, values from earlier steps).

import { editStep } from "./dialog.js";
import { $, fill, h } from "./dom.js";
import { numberOf, stepAt, withList } from "./places.js";
import { outcomeChoices, outcomeText, state } from "./state.js";
import { label, paramSummary } from "./steptext.js";

/** The outcome choices of `owner`'s process that have no branch there yet (`keep` stays offered). */
export function freeOutcomes(owner, keep) {
  const taken = Object.keys(owner.on || {});
  return outcomeChoices(owner.command).filter((c) => c.outcome === keep || !taken.includes(c.outcome));
}

/** A branch in words: "If step 2 (Localise part) ends with NoPartFound". */
export function branchText(steps, place, outcome) {
  return `If step ${numberOf(steps, place)} (${label(stepAt(steps, place).command)}) ends with ${outcome}`;
}

/** The commands a branch step may take: those the cell offers (every known one before the cell is known). */
function commands() {
  const offered = state.commands ? state.commands.offered.map((o) => o.command) : [...state.processes.keys()];
  return offered.filter((c) => state.processes.has(c));
}

/** One open branch dialog: the step at `place`, its branch `old` (null for a new one), the steps being edited. */
class BranchEdit {
  constructor(place, old) {
    this.place = place;
    this.old = old;
    this.draft = old ? [...stepAt(state.task.steps, place).on[old]] : [];
  }

  get outcome() {
    return $("#branch-outcome").value;
  }

  /** The task's steps with this branch as it is being edited (under the outcome chosen now). */
  steps() {
    const prefix = (outcome) => [...this.place, outcome];
    const without = this.old ? withList(state.task.steps, prefix(this.old), () => []) : state.task.steps;
    return this.outcome ? withList(without, prefix(this.outcome), () => this.draft) : without;
  }

  async open(j) {
    const outcome = this.outcome;
    if (!outcome) {
      $("#branch-error").textContent = "Choose the outcome the branch runs on first.";
      return;
    }
    const previous = j === undefined ? null : this.draft[j];
    const index = j === undefined ? this.draft.length : j;
    const command = previous ? previous.command : $("#branch-command").value;
    const step = await editStep(command, { steps: this.steps(), place: [...this.place, outcome, index] }, previous);
    if (!step) return;
    this.draft = [...this.draft];
    this.draft.splice(index, previous ? 1 : 0, step);
    this.render();
  }

  change(j, delta) {
    const draft = [...this.draft];
    if (delta === 0) draft.splice(j, 1);
    else [draft[j], draft[j + delta]] = [draft[j + delta], draft[j]];
    this.draft = draft;
    this.render();
  }

  item(step, j) {
    const name = `branch step ${j + 1} (${label(step.command)})`;
    const button = (cls, text, aria, fn, disabled = false) =>
      h("button", { type: "button", class: `${cls} quiet`, "aria-label": aria, disabled, onclick: fn }, text);
    return h("li", { class: "step", dataset: { command: step.command } },
      h("div", { class: "step-head" },
        h("span", { class: "step-no", "aria-hidden": "true" }, String(j + 1)),
        h("div", { class: "step-main" },
          h("span", { class: "step-cmd" }, label(step.command), " ", h("code", {}, step.command),
            step.name ? h("span", { class: "badge step-name" }, step.name) : null),
          h("span", { class: "step-detail" }, paramSummary(step))),
        h("span", { class: "step-actions" },
          button("edit", "Edit", `Edit ${name}`, () => this.open(j)),
          button("up", "↑", `Move ${name} up`, () => this.change(j, -1), j === 0),
          button("down", "↓", `Move ${name} down`, () => this.change(j, 1), j === this.draft.length - 1),
          button("remove danger", "Remove", `Remove ${name}`, () => this.change(j, 0)))));
  }

  render() {
    fill($("#branch-steps"), this.draft.map((s, j) => this.item(s, j)));
    $("#branch-empty").hidden = this.draft.length > 0;
    $("#branch-error").textContent = "";
  }

  /** What is wrong with the branch as it is ("" when nothing), said as the fix. */
  refusal() {
    if (!this.outcome) return "Choose the outcome the branch runs on.";
    if (this.draft.length === 0) return "A branch needs at least one step: add one, or cancel.";
    return "";
  }
}

function fillChoices(edit) {
  const owner = stepAt(state.task.steps, edit.place);
  const outcomes = freeOutcomes(owner, edit.old);
  fill($("#branch-outcome"), outcomes.length ? null : h("option", { value: "" }, "no outcome left to branch on"),
    outcomes.map((c) => h("option", { value: c.outcome, selected: c.outcome === edit.old }, outcomeText(c))));
  fill($("#branch-command"), commands().map((c) => h("option", { value: c }, label(c))));
  $("#branch-title").textContent = edit.old
    ? `Edit branch: ${branchText(state.task.steps, edit.place, edit.old)}`
    : `Add a branch to step ${numberOf(state.task.steps, edit.place)} (${label(owner.command)})`;
}

/**
 * Open the branch dialog for the step at `place`: a new branch, or its branch on `old` to change.
 * Resolves to {outcome, steps}, or null when cancelled.
 */
export function editBranch(place, old = null) {
  const dialog = $("#branch-dialog");
  const form = $("#branch-form");
  const edit = new BranchEdit(place, old);
  fillChoices(edit);
  edit.render();
  const add = () => edit.open();
  return new Promise((resolve) => {
    const done = (value) => {
      form.removeEventListener("submit", submit);
      $("#branch-cancel").removeEventListener("click", cancel);
      $("#branch-add").removeEventListener("click", add);
      dialog.removeEventListener("cancel", cancel);
      if (dialog.open) dialog.close();
      resolve(value);
    };
    const cancel = (e) => { e.preventDefault(); done(null); };
    const submit = (e) => {
      e.preventDefault();
      const why = edit.refusal();
      $("#branch-error").textContent = why;
      if (!why) done({ outcome: edit.outcome, steps: edit.draft });
    };
    form.addEventListener("submit", submit);
    $("#branch-cancel").addEventListener("click", cancel);
    $("#branch-add").addEventListener("click", add);
    dialog.addEventListener("cancel", cancel);
    dialog.showModal();
    $("#branch-outcome").focus();
  });
}
