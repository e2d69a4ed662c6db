"""Data flow of a task: every parameter taken from an earlier step's output must be able to get it.

A step's parameter may take the output of an earlier, named step
(``pick_pose: {from: localize, output: part_pose}``). The check refuses, at the line of
the value: a source step that does not exist or does not come earlier, an output the
source step's process does not give back, and an output whose datatype, unit or
quantity does not fit the parameter (the output's quantity must be the parameter's or a
more specific one). In a cell, the device bound to the output's role must report it: some
event of its chart carries a value of the output's name.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING

from plugnproduce.description.model import (
    Cell,
    Command,
    DeviceDescription,
    Link,
    Output,
    Parameter,
    ProcessDescription,
    Step,
    Task,
)
from plugnproduce.ontology.iris import PNP_IRI, local_name
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp.results import Problem, Reason, StepCheck
from plugnproduce.statechart.model import Send, walk

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

POSE = PNP_IRI + "Pose"


def link_problems(task: Task, knowledge: Knowledge) -> Iterator[Problem]:
    """One problem per link of the task's first round (a loop's first iteration) that cannot get its value."""
    one_round = task.steps[: len(task.steps) // max(task.repeat, 1)]
    later = {i for lp in task.loops for i in range(lp.first, lp.last + 1)}  # a loop's body is written once
    for step in one_round:
        process = knowledge.processes_by_id.get(step.command)
        if step.index in later:
            continue
        if process is None:
            continue  # an unknown command is a problem of its own
        for name, link in sorted(step.links().items()):
            if name not in {p.name for p in process.parameters}:
                yield _undeclared(task, step, name, process)
                continue
            named = _named_before(one_round, step)
            text, iris = _link_text(step, link, named, knowledge, process.parameter(name))
            text = text or _on_every_path(task, step, name, link, named)
            if text:
                where = task.where(step, name)
                yield Problem(step.index, step.command, "bad_link", Reason("bad_link", text, iris, (where,)), where,
                              parameter=name)


def _undeclared(task: Task, step: Step, name: str, process: ProcessDescription) -> Problem:
    """A link on a parameter the step's process does not declare (as params.lp finds a value on one)."""
    names = ", ".join(p.name for p in process.parameters)
    text = (f"step {step.index} ({step.command}): parameter {name} is not declared by {process.id} "
            f"(its parameters: {names})")
    where = task.where(step, name)
    return Problem(step.index, step.command, "unknown_param", Reason("unknown_param", text), where, parameter=name)


def _named_before(steps: tuple[Step, ...], step: Step) -> dict[str, Step]:
    """Each step name → the last step of that name before ``step`` (else its first after it)."""
    named = {s.name: s for s in reversed(steps) if s.name}
    named.update({s.name: s for s in steps[: step.index - 1] if s.name})
    return named


def _on_every_path(task: Task, step: Step, name: str, link: Link, named: dict[str, Step]) -> str:
    """What is wrong with a link whose source step runs only in a branch the consuming step is not in."""
    source = named.get(link.step)
    only = [b for b in task.branches if source is not None and b.holds(source.index) and not b.holds(step.index)]
    if source is None or not only:
        return ""
    return (f"step {step.index} ({step.command}): parameter {name} takes {link.output} from {link.step}, but step "
            f"{source.index} ({link.step}) runs only on {only[-1].path}; a step may take only an output produced "
            "on every path to it")


def _link_text(step: Step, link: Link, named: dict[str, Step], knowledge: Knowledge,
               parameter: Parameter) -> tuple[str, tuple[str, ...]]:
    """What is wrong with one link ("" if nothing), and the terms it rests on."""
    head = f"step {step.index} ({step.command}): parameter {parameter.name} takes {link.output} from {link.step}"
    source = named.get(link.step)
    if source is None:
        known = ", ".join(sorted(named)) or "none"
        return f"{head}, but no step is named {link.step!r}; named steps: {known}", ()
    if source.index >= step.index:
        return f"{head}, but step {source.index} ({link.step}) comes after it; a value must be produced first", ()
    process = knowledge.processes_by_id.get(source.command)
    if process is None:
        return "", ()
    if link.output not in {o.name for o in process.outputs}:
        outputs = ", ".join(o.name for o in process.outputs) or "none"
        return f"{head}, but {process.id} gives back no {link.output!r}; its outputs: {outputs}", (process.iri,)
    output = process.output(link.output)
    if link.offset is not None and output.datatype != POSE:
        return (f"{head} with an offset, but {link.output} is a {local_name(output.datatype)}; only a pose takes an "
                "offset [x, y, z, rx, ry, rz]", (output.datatype,))
    return _fit(head, output, parameter, knowledge.taxonomy)


def _fit(head: str, output: Output, parameter: Parameter, taxonomy: Taxonomy) -> tuple[str, tuple[str, ...]]:
    """Whether an output's datatype, unit and quantity fit a parameter."""
    if output.datatype != parameter.datatype:
        return (f"{head}, a {local_name(output.datatype)}; the parameter takes a {local_name(parameter.datatype)}",
                (output.datatype, parameter.datatype))
    if output.unit != parameter.unit:
        return (f"{head} in {output.unit or 'no unit'!s}; the parameter is in {parameter.unit or 'no unit'!s}",
                (output.iri, parameter.iri))
    if not taxonomy.is_a(output.quantity, parameter.quantity):
        return (f"{head}, a {taxonomy.label(output.quantity)}; the parameter takes a "
                f"{taxonomy.label(parameter.quantity)}", (output.quantity, parameter.quantity))
    return "", ()


def reports(device: DeviceDescription, value: str) -> bool:
    """Whether some protocol event of the device's chart carries a value called ``value``."""
    for node in walk(device.chart):
        if isinstance(node, Send) and any(p.name == value for p in node.params):
            command = Command.parse(node.event or "")
            if command is not None and command.kind == "event":
                return True
    return False


def unreported(task: Task, cell: Cell, steps: tuple[StepCheck, ...],
               processes: Mapping[str, ProcessDescription]) -> Iterator[Problem]:
    """One problem per link whose source step's device never reports the output."""
    one_round = task.steps[: len(task.steps) // max(task.repeat, 1)]
    later = {i for lp in task.loops for i in range(lp.first, lp.last + 1)}
    devices = {d.id: d for d in cell.devices}
    for step in one_round:
        if step.index in later or step.command not in processes:
            continue
        for name, link in sorted(step.links().items()):
            source = _named_before(one_round, step).get(link.step)
            process = processes.get(source.command) if source is not None else None
            if source is None or process is None or source.index > len(steps) or \
                    link.output not in {o.name for o in process.outputs}:
                continue  # a link problem of its own
            role = process.output(link.output).role
            bound = steps[source.index - 1].bindings  # without the role: no device plays it, a finding of its own
            device = devices.get(bound[role]) if role in bound else None
            if device is None or reports(device, link.output):
                continue
            text = (f"step {step.index} ({step.command}): parameter {name} takes {link.output} from {link.step}, "
                    f"but device '{device.id}' (role '{role}') reports no {link.output}: no event of its chart "
                    "carries a value of that name")
            where = task.where(step, name)
            yield Problem(step.index, step.command, "bad_link", Reason("bad_link", text, (), (where, device.where)),
                          where, role=role, device=device.id, parameter=name)
