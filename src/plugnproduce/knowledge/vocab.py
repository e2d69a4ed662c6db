"""The vocabulary of the loaded knowledge: what a description may name, and what each term implies."""

from __future__ import annotations

from plugnproduce.knowledge.libraries import Knowledge
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.taxonomy import Taxonomy

Entry = dict[str, object]


def curie(iri: str) -> str:
    """``pnp:Local`` for a term of the ``pnp`` namespace, else the full IRI."""
    return "pnp:" + iri[len(PNP_IRI):] if iri.startswith(PNP_IRI) else iri


ROOTS = (
    ("device_classes", "Device", "a new device class subclasses it"),
    ("skills", "Skill", "a new skill subclasses it (and names its mandatory states)"),
    ("state_concepts", "StateConcept", "a new state concept subclasses it"),
    ("quantities", "Quantity", "a new parameter quantity subclasses it"),
    ("outcomes", "Outcome", "a new process outcome subclasses it"),
)
"""The vocabulary's kinds: (key, root class in the ``pnp`` namespace, what a library's term of that kind does)."""


def _same(taxonomy: Taxonomy, a: str, b: str) -> bool:
    return taxonomy.is_a(a, b) and taxonomy.is_a(b, a)


def _equivalents(taxonomy: Taxonomy, iri: str) -> list[str]:
    """The other named classes equivalent to ``iri`` (``pnp:Released`` for ``pnp:Open``)."""
    return sorted(s for s in taxonomy.superclasses.get(iri, frozenset()) if s != iri and _same(taxonomy, s, iri))


def direct_parents(taxonomy: Taxonomy, iri: str, root: str) -> list[str]:
    """The direct named superclasses of ``iri`` under ``root`` (the root included); equivalent classes are not
    parents of each other."""
    ups = {s for s in taxonomy.superclasses.get(iri, frozenset()) if not taxonomy.is_a(s, iri)}
    direct = [s for s in ups if not any(o in ups and taxonomy.is_a(o, s) and not taxonomy.is_a(s, o) for o in ups)]
    return sorted(s for s in direct if taxonomy.is_a(s, PNP_IRI + root))


def _parents(taxonomy: Taxonomy, iri: str, root: str) -> list[str]:
    return sorted(curie(s) for s in direct_parents(taxonomy, iri, root))


def _term(taxonomy: Taxonomy, iri: str, root: str) -> Entry:
    return {"iri": iri, "name": curie(iri), "label": taxonomy.label(iri), "parents": _parents(taxonomy, iri, root),
            "equivalent": [curie(e) for e in _equivalents(taxonomy, iri)]}


def vocabulary(knowledge: Knowledge) -> dict[str, list[Entry]]:
    """The roots a library's terms subclass, device classes (with implied skills), skills (with mandatory
    states), state concepts, quantities (with the datatypes and units parameters give them), outcomes and
    processes."""
    t = knowledge.taxonomy
    quantities: dict[str, set[tuple[str, str]]] = {}
    for p in knowledge.processes:
        for par in p.parameters:
            quantities.setdefault(par.quantity, set()).add((curie(par.datatype), par.unit))
    return {
        "roots": [{"iri": PNP_IRI + root, "name": curie(PNP_IRI + root), "label": t.label(PNP_IRI + root),
                   "kind": key, "use": use} for key, root, use in ROOTS],
        "device_classes": [{**_term(t, c, "Device"), "skills": sorted(curie(s) for s in t.device_skills([c], []))}
                           for c in t.classes_of_kind("Device")],
        "skills": [{**_term(t, s, "Skill"), "mandatory_states": sorted(curie(m) for m in
                                                                        t.mandatory_states.get(s, ()))}
                   for s in t.classes_of_kind("Skill")],
        "state_concepts": [_term(t, c, "StateConcept") for c in t.classes_of_kind("StateConcept")],
        "quantities": [{**_term(t, q, "Quantity"),
                        "used_as": [{"datatype": d, "unit": u} for d, u in sorted(quantities.get(q, ()))]}
                       for q in t.classes_of_kind("Quantity")],
        "outcomes": [_term(t, c, "Outcome") for c in t.classes_of_kind("Outcome")],
        "processes": [_process(knowledge, p.id) for p in knowledge.processes],
    }


def _process(knowledge: Knowledge, command: str) -> Entry:
    p = knowledge.process(command)
    return {
        "command": p.id, "iri": p.iri, "label": p.label, "file": str(p.where),
        "roles": [{"role": r.name, "skill": curie(r.required_skill), "start": curie(r.start_concept),
                   "end": curie(r.end_concept)} for r in p.roles],
        "parameters": [{"name": x.name, "role": x.role, "quantity": curie(x.quantity), "datatype": curie(x.datatype),
                        "unit": x.unit, "min": x.minimum, "max": x.maximum, "default": x.default}
                       for x in p.parameters],
    }


def _also(e: Entry) -> str:
    same = e.get("equivalent") or []
    return f"  (equivalent: {', '.join(same)})" if same else ""  # type: ignore[arg-type]


def vocabulary_text(vocab: dict[str, list[Entry]]) -> list[str]:
    """The vocabulary as lines for a terminal."""
    lines = ["roots (every term of a library subclasses one):"]
    lines += [f"  {e['name']:<34} {e['use']}" for e in vocab["roots"]]
    lines.append("device classes (skills they imply):")
    lines += [f"  {e['name']:<34} {', '.join(e['skills']) or '-'}{_also(e)}"  # type: ignore[arg-type]
              for e in vocab["device_classes"]]
    lines.append("skills (mandatory state concepts):")
    lines += [f"  {e['name']:<34} {', '.join(e['mandatory_states']) or '-'}{_also(e)}"  # type: ignore[arg-type]
              for e in vocab["skills"]]
    lines.append("state concepts (parents):")
    lines += [f"  {e['name']:<34} {', '.join(e['parents'])}{_also(e)}"  # type: ignore[arg-type]
              for e in vocab["state_concepts"]]
    lines.append("quantities (datatype, unit as parameters use them):")
    for e in vocab["quantities"]:
        uses = ", ".join(f"{u['datatype']} {u['unit']}".strip() for u in e["used_as"]) or "-"  # type: ignore[attr-defined]
        lines.append(f"  {e['name']:<34} {uses}{_also(e)}")
    lines.append("outcomes (parents):")
    lines += [f"  {e['name']:<34} {', '.join(e['parents'])}{_also(e)}"  # type: ignore[arg-type]
              for e in vocab["outcomes"]]
    lines.append("processes (role: skill, start -> end; parameters):")
    for p in vocab["processes"]:
        lines.append(f"  {p['command']}  ({p['file']})")
        for r in p["roles"]:  # type: ignore[attr-defined]
            lines.append(f"    {r['role']}: {r['skill']}, {r['start']} -> {r['end']}")
        params = ", ".join(f"{x['name']} ({x['quantity']}, {x['role']})" for x in p["parameters"])  # type: ignore[attr-defined]
        lines.append(f"    parameters: {params or '-'}")
    return lines


def taxonomy_tree(taxonomy: Taxonomy) -> list[Entry]:
    """The taxonomy as a tree per root (devices, skills, state concepts, quantities, outcomes): each node names
    its equivalent classes together (``["pnp:Open", "pnp:Released"]``) and lists its children; a class under
    several parents appears under each."""
    out: list[Entry] = []
    for key, root, _ in ROOTS:
        top = PNP_IRI + root
        children: dict[str, set[str]] = {}
        for c in taxonomy.classes_of_kind(root):
            for parent in direct_parents(taxonomy, c, root):
                children.setdefault(_first(taxonomy, parent), set()).add(_first(taxonomy, c))
        out.append({"kind": key, "names": [curie(top)], "children": _branch(taxonomy, top, children, (top,))})
    return out


def vocabulary_tree(taxonomy: Taxonomy) -> list[str]:
    """:func:`taxonomy_tree` as indented lines, equivalent classes on one line (``pnp:Open ≡ pnp:Released``)."""
    lines: list[str] = []

    def show(node: Entry, depth: int) -> None:
        lines.append("  " * depth + " ≡ ".join(node["names"]))  # type: ignore[arg-type]
        for child in node["children"]:  # type: ignore[attr-defined]
            show(child, depth + 1)

    for root in taxonomy_tree(taxonomy):
        lines.append(f"{root['names'][0]}  ({str(root['kind']).replace('_', ' ')})")  # type: ignore[index]
        for child in root["children"]:  # type: ignore[attr-defined]
            show(child, 1)
    return lines


def _first(taxonomy: Taxonomy, iri: str) -> str:
    """The representative of ``iri``'s equivalence class: the first of its names."""
    return min([iri, *_equivalents(taxonomy, iri)])


def _branch(taxonomy: Taxonomy, node: str, children: dict[str, set[str]], path: tuple[str, ...]) -> list[Entry]:
    return [{"names": [curie(c) for c in [child, *_equivalents(taxonomy, child)]],
             "children": _branch(taxonomy, child, children, (*path, child))}
            for child in sorted(children.get(node, ()), key=curie) if child not in path]
