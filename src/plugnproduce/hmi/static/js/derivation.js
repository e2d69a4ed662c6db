// Explanations: the derivation collapsed to one sentence with expandable detail, the engineer's view
// (rule instances, axioms, file:line links that open the description at that line), and counterfactuals.

import { get } from "./api.js";
import { $, fill, h } from "./dom.js";

/** Turn the engineer's view on or off (kept for the session). */
export function initDerivations() {
  const box = $("#engineer-view");
  box.checked = sessionStorage.getItem("pnp-engineer") === "1";
  document.body.classList.toggle("engineer", box.checked);
  box.addEventListener("change", () => {
    document.body.classList.toggle("engineer", box.checked);
    sessionStorage.setItem("pnp-engineer", box.checked ? "1" : "0");
  });
  $("#source-close").addEventListener("click", () => $("#source-dialog").close());
}

/** Split "file:line" (the file may itself hold colons). */
function place(where) {
  const m = /^(.*):(\d+)$/.exec(where);
  return m ? { file: m[1], line: Number(m[2]) } : { file: where, line: 1 };
}

async function openSource(where) {
  const { file, line } = place(where);
  const dialog = $("#source-dialog");
  try {
    const src = await get(`/api/source?file=${encodeURIComponent(file)}&line=${line}`);
    $("#source-title").textContent = `${src.name}:${src.line}`;
    fill($("#source-lines"), src.lines.map((l) => h(l.number === src.line ? "mark" : "span",
      { class: "source-line", dataset: { line: l.number } }, `${String(l.number).padStart(4)}  ${l.text}\n`)));
  } catch (err) {
    $("#source-title").textContent = where;
    fill($("#source-lines"), h("span", { class: "error" }, err.message));
  }
  if (!dialog.open) dialog.showModal();
  const mark = $("#source-lines mark");
  if (mark) mark.scrollIntoView({ block: "center" });
}

function engineerPart(node) {
  const parts = [];
  if (node.detail) parts.push(h("code", { class: "detail" }, node.detail));
  if (node.kind === "owl" && node.inferred) parts.push(h("span", { class: "inferred" }, "inferred by HermiT"));
  if (node.where) {
    const name = String(node.where).split(/[\\/]/).pop();
    parts.push(h("a", { href: "#", class: "source", onclick: (e) => { e.preventDefault(); openSource(node.where); } },
      name));
  }
  return parts.length ? h("span", { class: "engineer-only" }, " ", parts) : null;
}

/** What a node rests on, in plain words ("rule", "ontology", "device chart"), and for a reason the answer
 * is no, the mark of the failing branch. */
function nodeHead(node) {
  const kind = h("span", { class: `kind kind-${node.kind}` }, node.source || node.kind);
  const mark = node.fails ? h("span", { class: "fails-mark" }, "✗ why not: ") : null;
  return [mark, kind, " ", node.text, engineerPart(node)];
}

function nodeItem(node) {
  const cls = node.fails ? "node fails" : "node";
  if (!node.children.length) return h("li", { class: cls }, nodeHead(node));
  return h("li", { class: cls }, h("details", {},
    h("summary", {}, nodeHead(node)), h("ul", {}, node.children.map(nodeItem))));
}

/**
 * An explanation's elements: the derivation (one sentence, expandable), then the counterfactuals —
 * as buttons when `apply(counterfactual)` can apply them, else as sentences — or that none exists.
 */
export function explanationView(ex, apply, canApply = () => false) {
  const root = ex.derivation;
  const tree = h("details", { class: "derivation" },
    h("summary", {}, root.text, engineerPart(root)), h("ul", { class: "tree" }, root.children.map(nodeItem)));
  let after = null;
  if (ex.counterfactuals.length) {
    const head = ex.answer ? "It rests on (checked by the reasoner):" : "What would make it work (checked by the reasoner):";
    after = h("div", { class: "counterfactuals" }, h("p", {}, head), h("ul", {}, ex.counterfactuals.map((c) =>
      h("li", {}, canApply(c) ? h("button", { type: "button", class: "counterfactual", onclick: () => apply(c) },
        c.text) : c.text, (c.side_effects || []).map((e) => h("p", { class: "side-effect" }, `Side effect: ${e}`))))));
  } else if (ex.none_exists) {
    after = h("p", { class: "hint none-exists" }, `Nothing to change: ${ex.none_exists}.`);
  }
  return [tree, after];
}
