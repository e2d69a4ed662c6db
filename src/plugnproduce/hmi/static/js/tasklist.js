// The task's steps as the editor lists them: each step with its actions, a loop's head before its body,
// and after a step each of its branches (its head, then its steps), indented by how deep they lie.
// Every step's item carries its row (the server's numbering of the editor's rows) and its place.

import { branchText, freeOutcomes } from "./branches.js";
import { h } from "./dom.js";
import { loopText } from "./loops.js";
import { numberOf, placeKey } from "./places.js";
import { loopOf, offer, state } from "./state.js";
import { label, paramSummary } from "./steptext.js";

function button(cls, text, aria, onclick, disabled = false) {
  return h("button", { type: "button", class: `${cls} quiet`, "aria-label": aria, disabled, onclick }, text);
}

function loopHead(loop, actions) {
  const index = state.task.loops.indexOf(loop);
  const text = loopText(loop);
  return h("li", { class: "loop-head", dataset: { first: loop.first, last: loop.last } },
    h("span", { class: "loop-text" }, text),
    h("span", { class: "step-actions" },
      button("edit-loop", "Edit loop", `Edit ${text}`, () => actions.loop(index)),
      button("remove-loop danger", "Remove loop", `Remove ${text}`, () => actions.removeLoop(loop))));
}

function branchHead(place, outcome, depth, actions) {
  const steps = state.task.steps;
  const n = numberOf(steps, place);
  return h("li", { class: `branch-head ${indent(place, depth + 1)}`, dataset: { place: placeKey(place), outcome } },
    h("span", { class: "branch-text" }, `${branchText(steps, place, outcome)}:`),
    h("span", { class: "step-actions" },
      button("edit-branch", "Edit branch", `Edit the ${outcome} branch of step ${n}`, () => actions.branch(place, outcome)),
      button("remove-branch danger", "Remove branch", `Remove the ${outcome} branch of step ${n}`,
        () => actions.removeBranch(place, outcome))));
}

/** How far an item is indented: its branch depth, one more inside a loop. */
function indent(place, depth) {
  return `depth-${Math.min(depth + (loopOf(place[0]) ? 1 : 0), 5)}`;
}

function classes(place, depth) {
  if (depth > 0) return `step in-branch ${indent(place, depth)}`;
  return loopOf(place[0]) ? "step in-loop" : "step";
}

/** A step's item: number, command, name, values, and its actions (edit, move, remove, add a branch). */
function stepItem(step, at, actions) {
  const { place, row, count, depth } = at;
  const n = numberOf(state.task.steps, place);
  const name = `step ${n} (${label(step.command)})`;
  const index = place[place.length - 1];
  const offered = !state.commands || offer(step.command);
  const li = h("li", { class: classes(place, depth), dataset: { row, command: step.command, place: placeKey(place) } },
    h("div", { class: "step-head" },
      h("span", { class: "step-no", "aria-hidden": "true" }, n),
      h("div", { class: "step-main" },
        h("span", { class: "step-cmd" }, label(step.command), " ", h("code", {}, step.command),
          step.name ? h("span", { class: "badge step-name" }, step.name) : null,
          offered ? null : h("span", { class: "badge warn" }, "not offered")),
        h("span", { class: "step-detail" }, paramSummary(step))),
      h("span", { class: "step-actions" },
        button("edit", "Edit", `Edit ${name}`, () => actions.edit(place)),
        button("up", "↑", `Move ${name} up`, () => actions.move(place, -1), index === 0),
        button("down", "↓", `Move ${name} down`, () => actions.move(place, 1), index === count - 1),
        button("remove danger", "Remove", `Remove ${name}`, () => actions.remove(place)),
        freeOutcomes(step).length ? button("add-branch", "Branch", `Add a branch to ${name}`,
          () => actions.branch(place)) : null)),
    h("ul", { class: "problems", "aria-label": `Problems of ${name}` }));
  li.addEventListener("keydown", (e) => {
    if (e.altKey && (e.key === "ArrowUp" || e.key === "ArrowDown")) {
      e.preventDefault();
      actions.move(place, e.key === "ArrowUp" ? -1 : 1);
    }
  });
  return li;
}

/** The items of the task's steps (a loop's head before its body, each branch after its step), with `actions`. */
export function taskItems(task, actions) {
  const items = [];
  let row = 0;
  const walk = (list, prefix, depth) => list.forEach((step, i) => {
    const place = [...prefix, i];
    const loop = depth === 0 ? (task.loops || []).find((l) => l.first === i) : null;
    if (loop) items.push(loopHead(loop, actions));
    items.push(stepItem(step, { place, row: row++, count: list.length, depth }, actions));
    for (const [outcome, inner] of Object.entries(step.on || {})) {
      items.push(branchHead(place, outcome, depth, actions));
      walk(inner, [...place, outcome], depth + 1);
    }
  });
  walk(task.steps, [], 0);
  return items;
}
