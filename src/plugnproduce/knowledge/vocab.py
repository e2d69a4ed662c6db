"""The vocabulary of the loaded knowledge: what a description may name, and what each term implies."""

from __future__ import annotations

from plugnproduce.knowledge.libraries import Knowledge
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP_IRI

Entry = dict[str, object]


def curie(iri: str) -> str:
    """``pnp:Local`` for a term of the ``pnp`` namespace, else the full IRI."""
    return "pnp:" + iri[len(PNP_IRI):] if iri.startswith(PNP_IRI) else iri


def _parents(taxonomy: Taxonomy, iri: str, root: str) -> list[str]:
    """The direct named superclasses of ``iri`` of the same kind (the root included)."""
    ups = {s for s in taxonomy.superclasses.get(iri, frozenset()) if s != iri}
    direct = [s for s in ups if not any(o != s and o in ups and taxonomy.is_a(o, s) for o in ups)]
    return sorted(curie(s) for s in direct if taxonomy.is_a(s, PNP_IRI + root))


def _term(taxonomy: Taxonomy, iri: str, root: str) -> Entry:
    return {"iri": iri, "name": curie(iri), "label": taxonomy.label(iri), "parents": _parents(taxonomy, iri, root)}


def vocabulary(knowledge: Knowledge) -> dict[str, list[Entry]]:
    """Device classes (with implied skills), skills (with mandatory states), state concepts,
    quantities (with the datatypes and units parameters give them) and processes."""
    t = knowledge.taxonomy
    quantities: dict[str, set[tuple[str, str]]] = {}
    for p in knowledge.processes:
        for par in p.parameters:
            quantities.setdefault(par.quantity, set()).add((curie(par.datatype), par.unit))
    return {
        "device_classes": [{**_term(t, c, "Device"), "skills": sorted(curie(s) for s in t.device_skills([c], []))}
                           for c in t.classes_of_kind("Device")],
        "skills": [{**_term(t, s, "Skill"), "mandatory_states": sorted(curie(m) for m in
                                                                        t.mandatory_states.get(s, ()))}
                   for s in t.classes_of_kind("Skill")],
        "state_concepts": [_term(t, c, "StateConcept") for c in t.classes_of_kind("StateConcept")],
        "quantities": [{**_term(t, q, "Quantity"),
                        "used_as": [{"datatype": d, "unit": u} for d, u in sorted(quantities.get(q, ()))]}
                       for q in t.classes_of_kind("Quantity")],
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


def vocabulary_text(vocab: dict[str, list[Entry]]) -> list[str]:
    """The vocabulary as lines for a terminal."""
    lines = ["device classes (skills they imply):"]
    lines += [f"  {e['name']:<34} {', '.join(e['skills']) or '-'}" for e in vocab["device_classes"]]  # type: ignore[arg-type]
    lines.append("skills (mandatory state concepts):")
    lines += [f"  {e['name']:<34} {', '.join(e['mandatory_states']) or '-'}"  # type: ignore[arg-type]
              for e in vocab["skills"]]
    lines.append("state concepts (parents):")
    lines += [f"  {e['name']:<34} {', '.join(e['parents'])}" for e in vocab["state_concepts"]]  # type: ignore[arg-type]
    lines.append("quantities (datatype, unit as parameters use them):")
    for e in vocab["quantities"]:
        uses = ", ".join(f"{u['datatype']} {u['unit']}".strip() for u in e["used_as"]) or "-"  # type: ignore[attr-defined]
        lines.append(f"  {e['name']:<34} {uses}")
    lines.append("processes (role: skill, start -> end; parameters):")
    for p in vocab["processes"]:
        lines.append(f"  {p['command']}  ({p['file']})")
        for r in p["roles"]:  # type: ignore[attr-defined]
            lines.append(f"    {r['role']}: {r['skill']}, {r['start']} -> {r['end']}")
        params = ", ".join(f"{x['name']} ({x['quantity']}, {x['role']})" for x in p["parameters"])  # type: ignore[attr-defined]
        lines.append(f"    parameters: {params or '-'}")
    return lines
