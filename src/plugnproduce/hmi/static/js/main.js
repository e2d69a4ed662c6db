// The page: load the processes and the cell, follow the server's events, wire every panel.

import { get, onTokenNeeded, setToken, token, tokenFromAddress } from "./api.js";
import { initCell, takeCell } from "./cell.js";
import { initCharts, renderChartChoices, showChart } from "./charts.js";
import { initDerivations } from "./derivation.js";
import { $ } from "./dom.js";
import { addStep, initEditor, renderTask, scheduleCheck } from "./editor.js";
import { initGoal } from "./goal.js";
import { initRun, renderRun, renderStart, takeDeviceState, takeRecord } from "./run.js";
import { loadTask, on, state } from "./state.js";
import { loadReports } from "./teach.js";
import { initZoom } from "./zoom.js";

function askToken() {
  const dialog = $("#token-dialog");
  const input = $("#token-input");
  input.value = token();
  return new Promise((resolve) => {
    const finish = (given) => {
      $("#token-form").removeEventListener("submit", submit);
      $("#token-cancel").removeEventListener("click", cancel);
      dialog.removeEventListener("cancel", cancel);
      if (dialog.open) dialog.close();
      resolve(given);
    };
    const submit = (e) => {
      e.preventDefault();
      if (!input.checkValidity()) {
        input.reportValidity();
        return;
      }
      setToken(input.value.trim());
      finish(true);
    };
    const cancel = (e) => { e.preventDefault(); finish(false); };
    $("#token-form").addEventListener("submit", submit);
    $("#token-cancel").addEventListener("click", cancel);
    dialog.addEventListener("cancel", cancel);
    dialog.showModal();
    input.focus();
  });
}

function setLive(live, text) {
  const el = $("#live");
  el.dataset.live = live;
  el.textContent = text;
}

function follow() {
  const loopback = ["127.0.0.1", "localhost", "[::1]"].includes(location.hostname);
  const url = loopback || !token() ? "/events" : `/events?token=${encodeURIComponent(token())}`;
  const events = new EventSource(url);
  const json = (fn) => (e) => fn(JSON.parse(e.data));
  events.addEventListener("open", () => setLive("live", "live"));
  events.addEventListener("error", () => setLive("lost", "reconnecting…"));
  events.addEventListener("cell", json((data) => {
    takeCell(data);
    renderChartChoices();
    loadReports();
    if (data.change) scheduleCheck();
  }));
  events.addEventListener("device-state", json(takeDeviceState));
  events.addEventListener("run", json(takeRecord));
  events.addEventListener("run-snapshot", json((run) => {
    state.run = run;
    renderRun();
  }));
}

async function boot() {
  tokenFromAddress();
  onTokenNeeded(askToken);
  $("#token-button").addEventListener("click", askToken);
  const [processes, cell, catalogue] = await Promise.all([get("/api/processes"), get("/api/cell"), get("/api/catalogue")]);
  for (const p of processes) state.processes.set(p.command, p);
  state.pluggable = cell.pluggable;
  state.catalogue = catalogue;
  await loadReports();
  initCell({ onAdd: addStep, onChart: showChart });
  initDerivations();
  initEditor();
  initGoal();
  initCharts();
  initZoom();
  loadTask();
  renderTask();
  on("cell", () => renderTask());
  on("task", renderStart);
  on("check", renderStart);
  follow();
  await initRun();
  scheduleCheck();
  document.body.dataset.ready = "true";
}

boot().catch((err) => {
  setLive("lost", `failed to load: ${err.message}`);
});
