"""Structure checks the schema and the shapes cannot express.

Commands use the protocol the device declares; initial states exist; a process
chart's concepts are state concepts, its ``pnp:params`` name its own parameters and
its ``In()`` conditions name states of other regions; a task names known commands,
roles and parameters.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterator

from plugnproduce.description.model import Command, DeviceDescription, ProcessDescription, Task
from plugnproduce.description.outcomes import flow_findings
from plugnproduce.ontology.iris import local_name
from plugnproduce.ontology.names import did_you_mean
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.validation.findings import Finding


def device_problems(device: DeviceDescription) -> Iterator[Finding]:
    """Problems of a device's chart that concern its metadata."""
    file = device.chart_file
    ids = {s.id for s in device.states}
    if device.initial not in ids:
        yield Finding(file, 1, f"initial state {device.initial!r} is not a state of the chart")
    for t in (*device.transitions, *device.stops):
        commands = [c for c in (Command.parse(t.event) if t.event else None, *t.sends) if c is not None]
        for c in commands:
            if c.protocol != device.protocol:
                yield Finding(
                    file,
                    t.line or 0,
                    f"command {c.event} uses protocol {c.protocol}, but device {device.id} declares "
                    f"{device.protocol}; expected {device.protocol}.{c.kind}.{c.name}",
                )


def process_problems(process: ProcessDescription, taxonomy: Taxonomy) -> Iterator[Finding]:
    """Problems of a process's chart: concepts, parameters and synchronisation."""
    file = process.chart_file
    all_states = {s.id: r.name for r in process.roles for s in r.region}
    params = {p.name: p for p in process.parameters}
    for p in process.parameters:
        if p.role not in {r.name for r in process.roles}:
            yield Finding(p.where.file, p.where.line or 0, f"parameter {p.name!r} is for role {p.role!r}, "
                          f"which process {process.id} does not have")
    for role in process.roles:
        for o in role.region[-1].outcomes:
            if not taxonomy.is_kind(o, "Outcome"):
                yield Finding(file, role.region[-1].line or 0, f"state {role.region[-1].id!r} names outcome "
                              f"{local_name(o)}, which is not an outcome of the ontology"
                              + did_you_mean(o, taxonomy.classes_of_kind("Outcome")))
        for s in role.region:
            if not taxonomy.is_kind(s.concept, "StateConcept"):
                yield Finding(file, s.line or 0, f"state {s.id!r} is annotated with {local_name(s.concept)}, "
                              "which is not a state concept of the ontology"
                              + did_you_mean(s.concept, taxonomy.classes_of_kind("StateConcept")))
            for name in s.params:
                if name not in params:
                    yield Finding(file, s.line or 0, f"transition into {s.id!r} consumes parameter {name!r}, "
                                  f"which process {process.id} does not declare")
                elif params[name].role != role.name:
                    yield Finding(file, s.line or 0, f"parameter {name!r} is for role {params[name].role!r}, "
                                  f"but region {role.name!r} consumes it")
            if s.waits_for is not None and all_states.get(s.waits_for, role.name) == role.name:
                yield Finding(file, s.line or 0, f"state {s.id!r} waits for In('{s.waits_for}'), "
                              "which is not a state of another region")


def flow_problems(task: Task, processes: dict[str, ProcessDescription], taxonomy: Taxonomy) -> Iterator[Finding]:
    """Branches and loops on outcomes: an unknown outcome, a branch that can never run, a loop that never
    ends (or never goes on) on its outcome."""
    for f in flow_findings(task, processes, taxonomy):
        yield Finding(task.file, f.line or 0, f.text)


def task_problems(task: Task, processes: dict[str, ProcessDescription], taxonomy: Taxonomy) -> Iterator[Finding]:
    """Problems of a task that need no cell: unknown commands, roles, parameters, and outcomes of branches and loops."""
    yield from flow_problems(task, processes, taxonomy)
    n = len(task.steps) // task.repeat
    for step in task.steps[:n]:
        line = step.line or 0
        process = processes.get(step.command)
        if process is None:
            close = difflib.get_close_matches(step.command, sorted(processes), n=2)
            hint = f"did you mean {' or '.join(close)}?" if close else f"expected one of {', '.join(sorted(processes))}"
            yield Finding(task.file, line, f"step {step.index}: unknown process command {step.command!r}; {hint}")
            continue
        roles = {r.name for r in process.roles}
        for role in step.bind:
            if role not in roles:
                yield Finding(task.file, line, f"step {step.index}: {step.command} has no role {role!r}; "
                              f"expected one of {', '.join(sorted(roles))}")
        names = {p.name for p in process.parameters}
        for name in step.params:
            if name not in names:
                expected = ", ".join(sorted(names)) or "none"
                yield Finding(task.file, line, f"step {step.index}: {step.command} has no parameter {name!r}; "
                              f"expected one of {expected}")
