"""Which values taken from earlier steps' outputs the check proves within the consuming device's contract.

A value a device reports is known only at run time, where the executor's monitor holds it to the
contract of the device it goes to. Where the producing device declares the range of the output
(:mod:`plugnproduce.description.quantities.ranges`), the check proves more: a pose reported within 1.2 m of the
base, lifted by an offset of 0.2 m, stays within a robot's reach of 1.45 m. Each link is said to be
either proven safe or checked at run time, with the reason.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING

from plugnproduce.description.model import Argument, Cell, Link, ProcessDescription, Step, Task
from plugnproduce.description.quantities.contracts import kind_of
from plugnproduce.description.quantities.ranges import OutputRange, output_ranges
from plugnproduce.description.quantities.units import UnitError, convert, reach_length
from plugnproduce.reasoning.asp.results import CheckResult, LinkSafety
from plugnproduce.reasoning.checks.contracts import contracts_for

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge


def link_safety(task: Task, cell: Cell, result: CheckResult, knowledge: Knowledge) -> tuple[LinkSafety, ...]:
    """Per link of the task as written (a loop's body once), whether its value is proven within the contract."""
    if len(result.steps) != len(task.steps):
        return ()
    return tuple(_links(task, cell, result, knowledge.processes_by_id))


def _links(task: Task, cell: Cell, result: CheckResult,
           processes: Mapping[str, ProcessDescription]) -> Iterator[LinkSafety]:
    devices = {d.id: d for d in cell.devices}
    later = {i for lp in task.loops for i in range(lp.first, lp.last + 1)}
    for step in task.one_round():
        process = processes.get(step.command)
        if process is None or step.index in later:
            continue
        for name, link in sorted(step.links().items()):
            source = _source(task, step, link)
            producer = processes.get(source.command) if source is not None else None
            outputs = {o.name: o for o in producer.outputs} if producer is not None else {}
            par = next((p for p in process.parameters if p.name == name), None)
            consumer = devices.get(result.steps[step.index - 1].bindings.get(par.role, "")) if par else None
            if source is None or par is None or consumer is None or link.output not in outputs:
                continue  # a link problem of its own
            reporter = devices.get(result.steps[source.index - 1].bindings.get(outputs[link.output].role, ""))
            declared = output_ranges(reporter).get(link.output) if reporter is not None else None
            why = _unproven(contracts_for(consumer, par.quantity), declared, link, consumer.id,
                            reporter.id if reporter else "its device")
            yield LinkSafety(step.index, step.command, name, f"{link.step}.{link.output}", consumer.id,
                             why.startswith("proven:"), why.removeprefix("proven: "))


def _source(task: Task, step: Step, link: Link) -> Step | None:
    """The step whose output ``link`` takes: the last of that name before ``step``."""
    return next((s for s in reversed(task.steps[: step.index - 1]) if s.name == link.step), None)


def _unproven(contracts: list[Argument], declared: OutputRange | None, link: Link, device: str,
              reporter: str) -> str:
    """Why the link's value is not proven within every contract, or ``proven: …`` with the proof."""
    if any(kind_of(c.datatype) == "integer" for c in contracts):  # no device declares its outputs whole
        return f"{device} takes a whole number; {reporter} does not promise one for {link.output}"
    limited = [c for c in contracts if c.reach is not None or c.minimum is not None or c.maximum is not None]
    if not limited:
        return f"proven: {device} sets no limits on it; its type and size are checked at run time"
    if declared is None:
        return f"{reporter} declares no range for {link.output}"
    proofs = []
    for contract in limited:
        step = _reach(contract, declared, link, device, reporter) or _limits(contract, declared, device, reporter)
        if not step.startswith("proven: "):
            return step
        proofs.append(step.removeprefix("proven: "))
    return "proven: " + "; ".join(dict.fromkeys(proofs))


def _reach(contract: Argument, declared: OutputRange, link: Link, device: str, reporter: str) -> str:
    if contract.reach is None:
        return ""
    try:  # each reach in the length of its own pose unit (metres where it names none)
        mine, theirs = reach_length(declared.unit), reach_length(contract.unit)
    except UnitError as exc:
        return f"{reporter}'s reach of {link.output} cannot be compared with {device}'s ({exc})"
    if declared.reach is None:
        return f"{reporter} declares no reach for {link.output}; {device} reaches {contract.reach:g} {theirs}"
    lift = math.dist(link.offset[:3], (0.0, 0.0, 0.0)) if link.offset is not None else 0.0
    plus = f" plus an offset of {lift:g} {mine}" if link.offset is not None else ""
    said = f"{reporter} reports {link.output} within {declared.reach:g} {mine} of the base{plus}"
    if convert(declared.reach + lift, mine, theirs) > contract.reach:
        return f"{said}, and {device} reaches only {contract.reach:g} {theirs}"
    return f"proven: {said}; {device} reaches {contract.reach:g} {theirs}"


def _limits(contract: Argument, declared: OutputRange, device: str, reporter: str) -> str:
    unit = f" {contract.unit}" if contract.unit else ""
    try:
        low = convert(declared.minimum, declared.unit, contract.unit) if declared.minimum is not None else None
        high = convert(declared.maximum, declared.unit, contract.unit) if declared.maximum is not None else None
    except UnitError as exc:
        return f"{reporter}'s range of {declared.output} is in {declared.unit}, not {contract.unit} ({exc})"
    if contract.minimum is not None and (low is None or low < contract.minimum):
        return f"{reporter} does not promise {declared.output} at least {contract.minimum:g}{unit}, {device}'s minimum"
    if contract.maximum is not None and (high is None or high > contract.maximum):
        return f"{reporter} does not promise {declared.output} at most {contract.maximum:g}{unit}, {device}'s maximum"
    return f"proven: {reporter} reports {declared.output} within {device}'s limits"
