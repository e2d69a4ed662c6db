"""Plain JSON views of the descriptions and run journals, as the HTTP API and the page show them."""

from __future__ import annotations

from typing import Any

from plugnproduce import service
from plugnproduce.service import (
    Cell,
    DeviceDescription,
    Loop,
    Output,
    Parameter,
    ProcessDescription,
    Step,
    Task,
    Taxonomy,
    concept_value,
    describe,
    local_name,
    plain_value,
)

DATATYPES = {"decimal": "decimal", "integer": "integer", "boolean": "boolean", "string": "string", "Pose": "pose"}
"""Local name of a parameter's ``pnp:datatype`` → the kind of field the parameter dialog shows."""


def device_json(device: DeviceDescription, taxonomy: Taxonomy, state: str | None = None) -> dict[str, Any]:
    """A device as ``pnp discover --json`` shows it (:func:`plugnproduce.service.device_view`), with its cost,
    states, the state concepts they stand for (as a goal's ``end`` names them), chart picture and (when known) its
    current chart state."""
    concept = None
    if state is not None:
        try:
            concept = device.state(state).concept
        except KeyError:
            concept = None
    return {
        **service.device_view(device, taxonomy),
        "cost": device.cost,
        "state": state,
        "state_concept": taxonomy.label(concept) if concept else None,
        "states": [s.id for s in device.states],
        "concepts": list(dict.fromkeys(concept_value(s.concept) for s in device.states if s.concept)),
        "chart": f"/api/charts/device/{device.id}.svg",
    }


def cell_json(cell: Cell, taxonomy: Taxonomy, states: dict[str, str]) -> dict[str, Any]:
    """A cell and its devices with their current states."""
    return {"name": cell.name,
            "devices": [device_json(d, taxonomy, states.get(d.id, d.initial)) for d in cell.devices]}


def _pose(value: object) -> object:
    if isinstance(value, str):
        try:
            return [float(v) for v in value.split()]
        except ValueError:
            return value
    return value


def parameter_json(p: Parameter, taxonomy: Taxonomy) -> dict[str, Any]:
    """A parameter: what its dialog field needs (name, datatype, unit, range, default, role)."""
    kind = DATATYPES.get(local_name(p.datatype), local_name(p.datatype))
    return {
        "name": p.name,
        "label": p.name.replace("_", " "),
        "datatype": kind,
        "unit": p.unit,
        "min": p.minimum,
        "max": p.maximum,
        "default": _pose(p.default) if kind == "pose" else p.default,
        "role": p.role,
        "quantity": taxonomy.label(p.quantity),
        "quantity_name": local_name(p.quantity),
    }


def output_json(o: Output, taxonomy: Taxonomy) -> dict[str, Any]:
    """An output: what a later step's parameter must be to take it (datatype, unit, quantity)."""
    return {"name": o.name, "label": o.name.replace("_", " "), "role": o.role,
            "datatype": DATATYPES.get(local_name(o.datatype), local_name(o.datatype)), "unit": o.unit,
            "quantity": taxonomy.label(o.quantity)}


def outcome_choices(p: ProcessDescription, taxonomy: Taxonomy) -> list[dict[str, Any]]:
    """The outcomes a branch on a step of ``p`` (or a loop's ``until``/``while``) may name: each outcome ``p``
    may end with, then each more general outcome they fall under (``NoPartFound`` for ``BinEmpty``), with the
    outcomes of ``p`` it covers."""
    ends = list(dict.fromkeys(p.outcomes))
    broader = [o for o in taxonomy.classes_of_kind("Outcome") if o not in ends]
    choices = []
    for o in ends + broader:
        covers = [concept_value(e) for e in ends if taxonomy.is_a(e, o)]
        if covers:
            choices.append({"outcome": concept_value(o), "label": taxonomy.label(o), "covers": covers})
    return choices


def process_json(p: ProcessDescription, taxonomy: Taxonomy) -> dict[str, Any]:
    """A process: its command, label, roles (required skill, start and end states), parameters, the outputs
    later steps may take, the outcomes it may end with, and the outcomes a branch or loop on it may name."""
    return {
        "command": p.id,
        "label": p.label,
        "comment": p.comment,
        "roles": [{"name": r.name, "skill": taxonomy.label(r.required_skill),
                   "start": taxonomy.label(r.start_concept), "end": taxonomy.label(r.end_concept)}
                  for r in p.roles],
        "parameters": [parameter_json(x, taxonomy) for x in p.parameters],
        "outputs": [output_json(o, taxonomy) for o in p.outputs],
        "outcomes": [concept_value(o) for o in dict.fromkeys(p.outcomes)],
        "outcome_choices": outcome_choices(p, taxonomy),
        "chart": f"/api/charts/process/{p.id}.svg",
    }


def _step_json(s: Step) -> dict[str, Any]:
    out: dict[str, Any] = {"name": s.name} if s.name else {}
    return {**out, "command": s.command, "bind": dict(s.bind),
            "params": {n: plain_value(v) for n, v in s.params.items()}}


def _loop_json(task: Task, loop: Loop) -> dict[str, Any]:
    head: dict[str, Any] = {"until": concept_value(loop.until)} if loop.until else {}
    if loop.while_outcome:
        head["while"] = concept_value(loop.while_outcome)
    if loop.max is not None:
        head["max"] = loop.max
    return {"loop": {**head, "steps": _items(task, loop.entry, loop.first - 1)}}


def _items(task: Task, first: int, last: int) -> list[dict[str, Any]]:
    """The items of step positions ``first`` to ``last`` as the task file nests them: a step with its branches
    (``on``), a loop holding its body once."""
    items: list[dict[str, Any]] = []
    index = first
    while index <= last:
        loop = task.loop_starting(index, last)
        if loop is not None:
            items.append(_loop_json(task, loop))
            index = loop.last + 1
            continue
        item = _step_json(task.steps[index - 1])
        branches = task.branches_of(index)
        if branches:
            item["on"] = {concept_value(b.outcome): _items(task, b.first, b.last) for b in branches}
        items.append(item)
        index = max([index] + [b.last for b in branches]) + 1
    return items


def task_json(task: Task) -> dict[str, Any]:
    """A task as the task file writes it: one round of its steps (a loop as one item holding its body, a step's
    branches under its ``on``), and how often they repeat."""
    steps = _items(task, 1, len(task.one_round()))
    return {"name": task.name, "description": task.description, "repeat": task.repeat, "steps": steps}


def editor_rows(task: Task) -> dict[int, tuple[int, int]]:
    """Step position → (editor row, round): the editor shows each step once (a loop's body once; a step's
    branches' steps after it, as positions number them), so a repeated step's round counts the repeats, and
    a loop's later iterations are its round 2."""
    rows: dict[int, tuple[int, int]] = {}
    one_round = len(task.one_round())
    row = 0
    for s in task.steps:
        loop = next((lp for lp in task.loops_at(s.index) if s.index >= lp.first), None)
        if loop is not None:
            rows[s.index] = (rows[s.index - (loop.first - loop.entry)][0], 2)
            continue
        if s.index > one_round:
            rows[s.index] = (rows[s.index - one_round][0], (s.index - 1) // one_round + 1)
            continue
        rows[s.index] = (row, 1)
        row += 1
    return rows


def run_json(run_id: str, records: list[dict[str, Any]], active: bool) -> dict[str, Any]:
    """What a run's journal says so far: status, current step (and every step position entered, from which
    a loop's iterations are counted), every device's state, the values that flowed, the branches taken, the
    fault if any."""
    start = next((r for r in records if r["kind"] == "start"), {})
    end = next((r for r in records if r["kind"] == "end"), None)
    steps = [r for r in records if r["kind"] == "step"]
    states = {str(k): str(v) for k, v in dict(start.get("states") or {}).items()}
    for r in records:
        if r["kind"] == "state":
            states[str(r["device"])] = str(r["state"])
    if end is not None:
        status = str(end.get("outcome", "failed"))
    else:
        status = "running" if active else "crashed"
    return {
        "run": run_id,
        "task": start.get("task"),
        "cell": start.get("cell"),
        "speed": start.get("speed"),
        "status": status,
        "steps": start.get("steps"),
        "step": steps[-1] if steps else None,
        "visited": [{"step": r.get("step"), "seq": r.get("seq")} for r in steps],
        "values": [r for r in records if r["kind"] == "value"],
        "branches": [r for r in records if r["kind"] == "branch"],
        "states": states,
        "faults": [r for r in records if r["kind"] == "fault"],
        "end": end,
        "lines": [describe(r) for r in records],
        "seq": records[-1].get("seq", len(records)) if records else 0,
    }
