// Pictures of device, process and generated task charts, and the generated SCXML to download.

import { post } from "./api.js";
import { $, fill, h } from "./dom.js";
import { state, taskBody } from "./state.js";

/** Show the picture at `url` with a caption. */
export function showChart(url, caption) {
  const img = $("#chart-img");
  img.hidden = false;
  img.alt = caption;
  img.src = url;
  $("#chart-caption").textContent = caption;
  const pick = $("#chart-pick");
  const option = [...pick.options].find((o) => o.value === url);
  pick.value = option ? url : "";
}

/** Fill the chart picker: the cell's and catalogue's devices, every process, the generated charts. */
export function renderChartChoices() {
  const pick = $("#chart-pick");
  const current = pick.value;
  const devices = new Map();
  for (const d of [...(state.cell ? state.cell.devices : []), ...state.catalogue]) devices.set(d.id, d);
  fill(pick,
    h("option", { value: "" }, "choose a chart…"),
    state.generated.length ? h("optgroup", { label: "Generated for the task" },
      state.generated.map((c) => h("option", { value: c.svg }, c.name))) : null,
    h("optgroup", { label: "Device State Charts" },
      [...devices.values()].map((d) => h("option", { value: d.chart }, `${d.id} (${d.classes.join(", ")})`))),
    h("optgroup", { label: "General Process State Charts" },
      [...state.processes.values()].map((p) => h("option", { value: p.chart }, `${p.label} (${p.command})`))));
  pick.value = [...pick.options].some((o) => o.value === current) ? current : "";
}

function renderLinks() {
  fill($("#chart-links"), state.generated.map((c) => h("li", {},
    h("a", { href: c.scxml, download: c.name }, c.name), ` (${c.kind})`)));
}

/** Generate the task's code and show its Task State Chart. */
export async function generate() {
  const caption = $("#chart-caption");
  try {
    const result = await post("/api/task/generate", taskBody());
    if (!result.plausible) {
      caption.textContent = `No code generated: ${result.problems.length ? result.problems[0].text : "the task is not plausible"}`;
      return;
    }
    state.generated = result.charts;
    renderChartChoices();
    renderLinks();
    const main = result.charts.find((c) => c.kind === "task") || result.charts[0];
    showChart(main.svg, `Task State Chart ${main.name}`);
    $("#charts").scrollIntoView({ behavior: "smooth", block: "start" });
  } catch (err) {
    caption.textContent = err.message;
  }
}

export function initCharts() {
  $("#chart-pick").addEventListener("change", (e) => {
    const option = e.target.selectedOptions[0];
    if (e.target.value) showChart(e.target.value, option.textContent);
  });
  $("#generate").addEventListener("click", generate);
}
