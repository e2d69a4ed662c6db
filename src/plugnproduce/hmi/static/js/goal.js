// The Goal view: state what must happen (a goal, as `pnp plan` reads it), see the plan the controller finds
// in the cell as it is now and its steps, and send it to the task editor.

import { api } from "./api.js";
import { $, announce, fill, h, showValue } from "./dom.js";
import { setTask } from "./editor.js";
import { editorTask } from "./state.js";

const EXAMPLE = `goal: empty-the-bin
achieve:
  - command: place
    params: {place_pose: [0.60, -0.20, 0.10, 0, 180, 0]}
until: BinEmpty
end: {gripper: Open}
`;

let planned = null;

function stepItem(s) {
  const bind = Object.entries(s.bind).map(([r, d]) => `${r} ${d}`).join(", ");
  const params = Object.entries(s.params).map(([n, v]) =>
    (v && v.from ? `${n} from ${v.from}.${v.output}` : `${n} ${showValue(v)}`)).join(", ");
  return h("li", { dataset: { command: s.command } }, h("strong", {}, s.command), bind ? ` on ${bind}` : "",
    params ? ` (${params})` : "");
}

function render(answer) {
  planned = answer.reachable ? answer : null;
  $("#goal-send").hidden = !planned;
  const status = $("#goal-status");
  if (!answer.reachable) {
    const buy = answer.purchase ? ` Buy ${answer.purchase.device} (${answer.purchase.label}, cost ${answer.purchase.cost}) and a plan exists.` : "";
    status.textContent = `No plan reaches goal ${answer.goal}: ${answer.reasons.join("; ")}.${buy}`;
    status.dataset.status = "unreachable";
    fill($("#goal-steps"), []);
    $("#goal-task").hidden = true;
    return;
  }
  const loop = answer.until ? `, repeated until ${answer.until}` : "";
  status.textContent = `Goal ${answer.goal}: planned, ${answer.steps.length} step(s)${loop}; the check finds it ${answer.plausible ? "plausible" : "implausible"}.`;
  status.dataset.status = "planned";
  fill($("#goal-steps"), answer.steps.map(stepItem));
  $("#goal-task").textContent = answer.text;
  $("#goal-task").hidden = false;
}

async function plan() {
  const status = $("#goal-status");
  status.textContent = "Planning…";
  status.dataset.status = "busy";
  try {
    render(await api("POST", "/api/goal/plan?filename=goal.yaml", $("#goal-text").value,
      { raw: true, contentType: "application/yaml" }));
    announce(status.textContent);
  } catch (err) {
    planned = null;
    $("#goal-send").hidden = true;
    status.textContent = err.message;
    status.dataset.status = "refused";
  }
}

function send() {
  if (!planned) return;
  const task = editorTask(planned.task);
  setTask(task, `Task ${task.name} planned from goal ${planned.goal} is in the task editor.`);
  $("#task").scrollIntoView();
}

/** Wire the Goal view (its text starts with the bin-emptying goal as an example). */
export function initGoal() {
  $("#goal-text").value = EXAMPLE;
  $("#goal-plan").addEventListener("click", plan);
  $("#goal-send").addEventListener("click", send);
}
