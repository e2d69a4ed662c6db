// Resume: on a failed or stopped run, re-plan the rest from the devices' states, show the plan, continue once
// the operator confirms it (the same controller call as `pnp resume`).

import { post } from "./api.js";
import { $, announce, fill, h } from "./dom.js";

let plan = null; // the plan shown, while it waits for confirmation
let started = () => {};

function hidePlan() {
  plan = null;
  $("#resume-plan").hidden = true;
}

function showPlan(answer) {
  plan = answer;
  const states = Object.entries(answer.states).map(([d, s]) => `${d} ${s}`).join(", ");
  $("#resume-what").textContent = `Plan: ${answer.plan}, ${answer.steps} step(s), from the devices' states (${states}).`;
  fill($("#resume-repairs"), (answer.repairs || []).map((edit) => h("li", {}, edit)));
  $("#resume-task").textContent = answer.task_file;
  $("#resume-plan").hidden = false;
  $("#resume-continue").focus();
}

async function replan(runId) {
  const status = $("#run-status");
  try {
    showPlan(await post(`/api/runs/${encodeURIComponent(runId)}/replan`, undefined, { auth: true }));
    announce("The rest of the run is planned: confirm it to continue.");
  } catch (err) {
    status.textContent = err.message;
    status.dataset.status = "refused";
  }
}

async function continueRun() {
  if (!plan) return;
  const shown = plan;
  try {
    const answer = await post(`/api/runs/${encodeURIComponent(shown.run)}/resume`, { states: shown.states }, { auth: true });
    hidePlan();
    started(answer);
  } catch (err) {
    $("#resume-what").textContent = err.message;
  }
}

/** Show "Resume" on a run that failed or was stopped (and no plan while a run runs). */
export function renderResume(run) {
  const resumable = Boolean(run && (run.status === "failed" || run.status === "stopped"));
  $("#run-resume").hidden = !resumable;
  if (!resumable || (plan && plan.run !== run.run)) hidePlan();
}

/** Wire Resume; `onStarted(view)` takes the new run's view from the server. */
export function initResume(onStarted, currentRun) {
  started = onStarted;
  $("#run-resume").addEventListener("click", () => {
    const run = currentRun();
    if (run) replan(run.run);
  });
  $("#resume-continue").addEventListener("click", continueRun);
  $("#resume-cancel").addEventListener("click", hidePlan);
}
