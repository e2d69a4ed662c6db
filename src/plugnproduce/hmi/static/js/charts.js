// Pictures of device, process and generated task charts, and the generated SCXML to download.
// A Task State Chart is drawn step by step: one step expanded into its regions, the others one box
// each with their process and binding; the step bar picks which.

import { get, post } from "./api.js";
import { $, fill, h } from "./dom.js";
import { state, taskBody } from "./state.js";
import { focusOn } from "./zoom.js";

// The task chart drawn step by step: its picture's address, steps, caption; `shown` counts pictures shown,
// `expanded` is the address of the picture with the step expanded now.
const steps = { url: null, list: [], caption: "", shown: 0, expanded: null };

function setPicture(url, caption) {
  const img = $("#chart-img");
  img.hidden = false;
  img.alt = caption;
  img.src = url;
  $("#chart-caption").textContent = caption;
}

/** Show the picture at `url` with a caption (a generated task chart step by step, its first step expanded). */
export function showChart(url, caption) {
  setPicture(url, caption);
  const pick = $("#chart-pick");
  const option = [...pick.options].find((o) => o.value === url);
  pick.value = option ? url : "";
  const task = state.generated.find((c) => c.kind === "task" && c.svg === url);
  $("#chart-steps").hidden = true;
  steps.url = null;
  steps.expanded = null;
  steps.shown += 1;
  if (task) loadSteps(task, caption, steps.shown);
}

function stepText(s) {
  const binding = Object.entries(s.binding).map(([role, device]) => `${role}: ${device}`).join(", ");
  return `${s.number} · ${s.command}${binding ? ` (${binding})` : ""}`;
}

async function loadSteps(task, caption, shown) {
  let list;
  try {
    list = await get(`${task.scxml}/steps`);
  } catch {
    return; // the picture stays, every step collapsed
  }
  if (shown !== steps.shown) return; // another chart was shown meanwhile
  Object.assign(steps, { url: task.svg, list, caption });
  if (!list.length) return;
  fill($("#chart-step"), h("option", { value: "" }, "none: every step collapsed"),
    list.map((s) => h("option", { value: String(s.number) }, stepText(s))));
  $("#chart-steps").hidden = false;
  expandStep(1);
}

/** Draw the task chart with step `n` expanded (none when `n` is 0 or empty), the others collapsed. */
export function expandStep(n) {
  if (!steps.url) return;
  const number = Math.max(0, Math.min(Number(n) || 0, steps.list.length));
  $("#chart-step").value = number ? String(number) : "";
  $("#step-prev").disabled = number <= 1;
  $("#step-next").disabled = number >= steps.list.length;
  const frame = $("#chart-frame");
  frame.dataset.step = String(number);
  const url = number ? `${steps.url}?step=${number}` : steps.url;
  steps.expanded = url;
  const img = $("#chart-img");
  if (number) img.addEventListener("load", () => focusStep(url, number), { once: true });
  setPicture(url, steps.caption);
  if (number) img.alt = `${steps.caption}, step ${stepText(steps.list[number - 1])} expanded`;
}

/** Where Graphviz drew the cluster `title` in the SVG at `url`, in the picture's pixels (null if nowhere). */
async function clusterBox(url, title, naturalWidth) {
  const doc = new DOMParser().parseFromString(await (await fetch(url)).text(), "image/svg+xml");
  const cluster = [...doc.querySelectorAll("g.cluster")].find((g) => g.querySelector("title")?.textContent === title);
  const graph = doc.querySelector("g.graph");
  const shape = cluster?.querySelector("path, polygon");
  if (!shape || !graph) return null;
  const view = (doc.documentElement.getAttribute("viewBox") || "").split(/[\s,]+/).map(Number);
  const shift = /translate\(([-\d.]+)[\s,]+([-\d.]+)\)/.exec(graph.getAttribute("transform") || "");
  const [tx, ty] = shift ? [Number(shift[1]), Number(shift[2])] : [0, 0];
  const points = [...(shape.getAttribute("d") || shape.getAttribute("points") || "").matchAll(/(-?[\d.]+),(-?[\d.]+)/g)];
  if (!points.length || !view[2]) return null;
  const xs = points.map((m) => Number(m[1]) + tx);
  const ys = points.map((m) => Number(m[2]) + ty);
  const r = naturalWidth / view[2];
  const [x, y] = [Math.min(...xs), Math.min(...ys)];
  return { x: x * r, y: y * r, w: (Math.max(...xs) - x) * r, h: (Math.max(...ys) - y) * r };
}

/** Bring step `number`, expanded in the picture at `url`, into view (once the picture has been fitted). */
async function focusStep(url, number) {
  let box = null;
  try {
    box = await clusterBox(url, `cluster_pnp_step_${number}`, $("#chart-img").naturalWidth);
  } catch {
    return; // the picture stays fitted
  }
  if (!box || steps.expanded !== url) return;
  focusOn(box);
  $("#chart-frame").dataset.focused = String(number);
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

/** Say by the Generate button what generating did: working, what it wrote (a link to the charts), or why not. */
function generateStatus(text, kind, link = null) {
  fill($("#generate-status"), h("span", { class: kind }, text), link);
}

/** Generate the task's code and show its Task State Chart. */
export async function generate() {
  const caption = $("#chart-caption");
  const button = $("#generate");
  button.disabled = true;
  generateStatus("Generating code…", "hint");
  try {
    const result = await post("/api/task/generate", taskBody());
    if (!result.plausible) {
      caption.textContent = `No code generated: ${result.problems.length ? result.problems[0].text : "the task is not plausible"}`;
      generateStatus(caption.textContent, "error");
      return;
    }
    if (!result.charts.length) {
      caption.textContent = `No code generated: ${unproved(result.verification)}`;
      generateStatus(caption.textContent, "error");
      return;
    }
    const proved = result.verification && result.verification.verdict === "proved"
      ? " (its program proved over every interleaving)" : "";
    generateStatus(`Generated ${result.charts.length} charts${proved}. `, "ok",
      h("a", { href: "#charts" }, "See them under Charts"));
    state.generated = result.charts;
    renderChartChoices();
    renderLinks();
    const main = result.charts.find((c) => c.kind === "task") || result.charts[0];
    showChart(main.svg, `Task State Chart ${main.name}`);
    $("#charts").scrollIntoView({ behavior: "smooth", block: "start" });
  } catch (err) {
    caption.textContent = err.message;
    generateStatus(`No code generated: ${err.message}`, "error");
  } finally {
    button.disabled = false;
  }
}

function unproved(verification) {
  if (!verification) return "the program was not generated";
  const last = verification.trace.length ? ` (${verification.trace[verification.trace.length - 1].where})` : "";
  return `verification ${verification.verdict} the program: ${verification.problem}${last}`;
}

export function initCharts() {
  $("#chart-pick").addEventListener("change", (e) => {
    const option = e.target.selectedOptions[0];
    if (e.target.value) showChart(e.target.value, option.textContent);
  });
  $("#generate").addEventListener("click", generate);
  $("#chart-step").addEventListener("change", (e) => expandStep(e.target.value));
  $("#step-prev").addEventListener("click", () => expandStep(Number($("#chart-step").value || 1) - 1));
  $("#step-next").addEventListener("click", () => expandStep(Number($("#chart-step").value || 0) + 1));
}
