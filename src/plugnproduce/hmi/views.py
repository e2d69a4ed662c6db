"""Plain JSON views of the descriptions and run journals, as the HTTP API and the page show them."""

from __future__ import annotations

from typing import Any

from plugnproduce import service
from plugnproduce.description.model import Cell, DeviceDescription, Parameter, ProcessDescription, Task, plain_value
from plugnproduce.executor.journal import describe
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import local_name

DATATYPES = {"decimal": "decimal", "integer": "integer", "boolean": "boolean", "string": "string", "Pose": "pose"}
"""Local name of a parameter's ``pnp:datatype`` → the kind of field the parameter dialog shows."""


def device_json(device: DeviceDescription, taxonomy: Taxonomy, state: str | None = None) -> dict[str, Any]:
    """A device as ``pnp discover --json`` shows it (:func:`plugnproduce.service.device_view`), with its cost,
    states, chart picture and (when known) its current chart state."""
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
    }


def process_json(p: ProcessDescription, taxonomy: Taxonomy) -> dict[str, Any]:
    """A process: its command, label, roles (required skill, start and end states) and parameters."""
    return {
        "command": p.id,
        "label": p.label,
        "comment": p.comment,
        "roles": [{"name": r.name, "skill": taxonomy.label(r.required_skill),
                   "start": taxonomy.label(r.start_concept), "end": taxonomy.label(r.end_concept)}
                  for r in p.roles],
        "parameters": [parameter_json(x, taxonomy) for x in p.parameters],
        "chart": f"/api/charts/process/{p.id}.svg",
    }


def task_json(task: Task) -> dict[str, Any]:
    """A task as the editor holds it: one round of its steps, and how often they repeat."""
    return {
        "name": task.name,
        "description": task.description,
        "repeat": task.repeat,
        "steps": [{"command": s.command, "bind": dict(s.bind),
                   "params": {n: plain_value(v) for n, v in s.params.items()}} for s in task.one_round()],
    }


def run_json(run_id: str, records: list[dict[str, Any]], active: bool) -> dict[str, Any]:
    """What a run's journal says so far: status, current step, every device's state, the fault if any."""
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
        "status": status,
        "steps": start.get("steps"),
        "step": steps[-1] if steps else None,
        "states": states,
        "faults": [r for r in records if r["kind"] == "fault"],
        "end": end,
        "lines": [describe(r) for r in records],
        "seq": records[-1].get("seq", len(records)) if records else 0,
    }
