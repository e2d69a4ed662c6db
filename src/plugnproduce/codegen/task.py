"""The Task State Chart (paper section 6.2, figure 6).

The Specific Process State Charts of a task's steps are concatenated in task order:
each step is a ``<parallel>`` with one region per device of the cell; a device the
step does not use gets a region that stays in the state its last step left it in.
The step's ``done.state`` event starts the next step; the last one ends in ``done``.
A device event that does not come within the device's command timeout, or an error
the executor raises, ends the task in ``failed``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lxml import etree

from plugnproduce.codegen.emit import el, pnp_attr, to_bytes
from plugnproduce.codegen.specific import RegionResult, controller_ids, specific_region
from plugnproduce.description.model import Cell, ChartTransition, Command, ProcessDescription, Step, Task
from plugnproduce.errors import PlugNProduceError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import concept_value, local_name

DONE, FAILED = "done", "failed"


class ImplausibleStep(PlugNProduceError):
    """A step needs a device in a state other than the one its last step left it in."""

    def __init__(self, step: Step, device: str, state: str, needed: str):
        self.step, self.device, self.state, self.needed = step, device, state, needed
        super().__init__(f"step {step.index} ({step.command}): device {device} is in state '{state}', "
                         f"but the step needs {local_name(needed)}")


@dataclass
class StepChart:
    """One step: its process, bindings and the regions generated for it."""

    step: Step
    process: ProcessDescription
    binding: dict[str, str]
    regions: list[RegionResult]
    element: etree._Element


@dataclass
class GeneratedTask:
    """What code generation produces for one task."""

    task: Task
    steps: list[StepChart]
    chart: etree._Element
    final_states: dict[str, str] = field(default_factory=dict)
    """Device → the chart state the task leaves it in."""

    def task_chart(self) -> bytes:
        """The Task State Chart as SCXML bytes."""
        return to_bytes(self.chart)

    def commands(self) -> list[tuple[int, str, Command]]:
        """Every device command in task order: (step, device, command from the device's side)."""
        return [(s.step.index, r.device.id, c) for s in self.steps for r in s.regions for _, c in r.commands]

    def device_paths(self, device: str) -> list[tuple[int, tuple[ChartTransition, ...]]]:
        """The transitions a device takes in its own chart, step by step."""
        return [(s.step.index, tuple(r.path)) for s in self.steps for r in s.regions if r.device.id == device]


def step_values(step: Step, process: ProcessDescription) -> dict[str, object]:
    """Parameter values of a step: the task's, and the process defaults for the rest."""
    values: dict[str, object] = {p.name: p.default for p in process.parameters if p.default is not None}
    values.update(step.params)
    return values


def generate_task(
    task: Task,
    cell: Cell,
    bindings: list[dict[str, str]],
    processes: dict[str, ProcessDescription],
    taxonomy: Taxonomy,
) -> GeneratedTask:
    """Generate the Task State Chart of a task whose steps are bound to devices (``bindings[i]`` for step i+1)."""
    current = {d.id: d.initial for d in cell.devices}
    steps: list[StepChart] = []
    root = el("scxml", version="1.0", datamodel="python", initial="task", name=f"task-{task.name}")
    body = el("state", id="task", initial="s1")
    body.append(el("transition", event="timeout error", target=FAILED))
    root.append(body)
    for step, binding in zip(task.steps, bindings, strict=True):
        process = processes[step.command]
        chart = _step(step, process, binding, cell, current, taxonomy)
        steps.append(chart)
        nxt = f"s{step.index + 1}" if step.index < len(task.steps) else DONE
        chart.element.append(el("transition", event=f"done.state.s{step.index}", target=nxt))
        body.append(chart.element)
    root.append(el("final", id=DONE))
    root.append(el("final", id=FAILED))
    return GeneratedTask(task, steps, root, dict(current))


def _step(
    step: Step,
    process: ProcessDescription,
    binding: dict[str, str],
    cell: Cell,
    current: dict[str, str],
    taxonomy: Taxonomy,
) -> StepChart:
    parallel = el("parallel", id=f"s{step.index}")
    parallel.set(pnp_attr("command"), process.id)
    parallel.set(pnp_attr("step"), str(step.index))
    ids = controller_ids(step.index, process, binding)
    values = step_values(step, process)
    regions = []
    for role in process.roles:
        device = cell.device(binding[role.name])
        state = current[device.id]
        concept = device.state(state).concept
        if concept is None or not taxonomy.is_a(concept, role.start_concept):
            raise ImplausibleStep(step, device.id, state, role.start_concept)
        region = specific_region(step.index, process, role, device, state, values, ids, taxonomy)
        _add_timeouts(region)
        current[device.id] = region.end_state
        regions.append(region)
    used = {r.device.id for r in regions}
    for region in sorted(regions, key=lambda r: r.device.id):
        parallel.append(region.element)
    for device in sorted(cell.devices, key=lambda d: d.id):
        if device.id not in used:
            parallel.append(_idle_region(step.index, device.id, current[device.id], cell, taxonomy))
    return StepChart(step, process, binding, regions, parallel)


def _idle_region(index: int, device: str, state: str, cell: Cell, taxonomy: Taxonomy) -> etree._Element:
    """A region for a device the step does not use: it stays in its state."""
    sid = f"s{index}_{device}".replace("-", "_")
    region = el("state", id=sid, initial=f"{sid}_stays")
    region.set(pnp_attr("device"), device)
    final = el("final", id=f"{sid}_stays")
    concept = cell.device(device).state(state).concept
    if concept:
        final.set(pnp_attr("concept"), concept_value(concept))
    final.set(pnp_attr("deviceState"), state)
    region.append(final)
    return region


def _add_timeouts(region: RegionResult) -> None:
    """Each state that waits for a device event gets a timer of the device's command timeout."""
    prefix = f"{region.device.id}."
    for state in region.element:
        waits = [t for t in state if t.get("event", "").startswith(prefix)]
        if not waits:
            continue
        timer = f"{state.get('id')}_timer"
        onentry = el("onentry")
        onentry.append(el("send", id=timer, event=f"timeout.{region.device.id}",
                          delay=f"{region.device.command_timeout:g}s"))
        onexit = el("onexit")
        onexit.append(el("cancel", sendid=timer))
        state.insert(0, onexit)
        state.insert(0, onentry)
