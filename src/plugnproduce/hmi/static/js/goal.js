// The Goal view: state what must happen (a goal, as `pnp plan` reads it, written by hand or by its form), see the
// plan the controller finds in the cell as it is now, its steps and its estimated cycle time, and send it to the
// task editor.

import { api } from "./api.js";
import { $, announce, fill, h, showValue } from "./dom.js";
import { setTask } from "./editor.js";
import { initGoalForm } from "./goalform.js";
import { editorTask } from "./state.js";

let planned = null;

function stepItem(s, seconds) {
  const bind = Object.entries(s.bind).map(([r, d]) => `${r} ${d}`).join(", ");
  const params = Object.entries(s.params).map(([n, v]) =>
    (v && v.from ? `${n} from ${v.from}.${v.output}` : `${n} ${showValue(v)}`)).join(", ");
  return h("li", { dataset: { command: s.command, seconds: seconds ?? "" } }, h("strong", {}, s.command),
    bind ? ` on ${bind}` : "", params ? ` (${params})` : "", seconds !== undefined ? `: ${seconds.toFixed(2)} s` : "");
}

/** The plan's estimated cycle time in words (`pnp check`'s estimate), or why there is none. */
function cycleText(answer) {
  const estimate = answer.cycle_time;
  if (!estimate) return "No cycle time is estimated: the plan is not plausible in the cell.";
  const per = answer.until ? " per iteration of the loop" : "";
  const notes = estimate.notes.length ? ` (${estimate.notes.join("; ")})` : "";
  return `Estimated cycle time: ${estimate.total_seconds.toFixed(2)} s${per}${notes}.`;
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
    $("#goal-cycle-time").hidden = true;
    $("#goal-task").hidden = true;
    return;
  }
  const loop = answer.until ? `, repeated until ${answer.until}` : "";
  status.textContent = `Goal ${answer.goal}: planned, ${answer.steps.length} step(s)${loop}; the check finds it ${answer.plausible ? "plausible" : "implausible"}.`;
  status.dataset.status = "planned";
  const seconds = new Map(((answer.cycle_time && answer.cycle_time.steps) || []).map((s) => [s.step, s.seconds]));
  fill($("#goal-steps"), answer.steps.map((s) => stepItem(s, seconds.get(s.step))));
  $("#goal-cycle-time").textContent = cycleText(answer);
  $("#goal-cycle-time").hidden = false;
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

/** Wire the Goal view (its form and text start with the bin-emptying goal as an example). */
export function initGoal() {
  initGoalForm();
  $("#goal-plan").addEventListener("click", plan);
  $("#goal-send").addEventListener("click", send);
}
