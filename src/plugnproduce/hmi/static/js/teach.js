// Teach-in in the step dialog: "Teach" beside a parameter whose quantity a device of the cell reports (the
// robot's TargetPose); the value is read from the device by its state query, held to its contracts, and put
// into the field (or the contract's refusal shown at the field).

import { get } from "./api.js";
import { h } from "./dom.js";
import { state } from "./state.js";

/** Which devices of the cell report which quantities: {device: [quantity]} (refreshed when the cell changes). */
export async function loadReports() {
  try {
    state.reports = (await get("/api/teach")).reports;
  } catch {
    state.reports = {};
  }
}

/** The device to teach parameter `p` from: the one its role is bound to in the dialog if it reports it, else any. */
function reporter(p, root) {
  const reports = state.reports || {};
  const gives = (d) => (reports[d] || []).includes(p.quantity_name);
  const role = p.role ? root.querySelector(`.field.role[data-role="${CSS.escape(p.role)}"]`) : null;
  const bound = role ? (role.dataset.fixed || (role.querySelector("select") || {}).value) : null;
  if (bound && gives(bound)) return bound;
  return Object.keys(reports).find(gives) || null;
}

function put(box, p, value) {
  const inputs = [...box.querySelectorAll("input")];
  if (p.datatype === "pose" && Array.isArray(value)) value.forEach((v, i) => { if (inputs[i]) inputs[i].value = String(v); });
  else if (inputs[0]) inputs[0].value = String(value);
}

/** A "Teach" button for the field `box` of parameter `p` (null when no device of the cell reports its quantity). */
export function teachButton(p, box, root) {
  if (!p.quantity_name || !Object.values(state.reports || {}).some((q) => q.includes(p.quantity_name))) return null;
  const said = h("span", { class: "hint taught", "aria-live": "polite" });
  const button = h("button", { type: "button", class: "teach", "aria-label": `Teach ${p.label}` }, "Teach");
  button.addEventListener("click", async () => {
    const device = reporter(p, root);
    const error = box.querySelector(".field-error");
    error.textContent = "";
    said.textContent = "";
    try {
      const taught = await get(`/api/teach/${encodeURIComponent(device)}/${encodeURIComponent(p.quantity_name)}`);
      if (!taught.accepted) {
        error.textContent = `taught value refused: ${taught.refused.join("; ")}`;
        return;
      }
      put(box, p, taught.value);
      said.textContent = `taught from ${taught.device} (${taught.state})`;
    } catch (err) {
      error.textContent = err.message;
    }
  });
  return h("span", { class: "teach-box" }, button, " ", said);
}
