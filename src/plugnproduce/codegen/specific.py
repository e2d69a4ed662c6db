"""Specific Process State Charts (paper section 6.1, figure 5).

For one step of a task: each role's region of the General Process State Chart is
bound to a device; for each of the region's transitions a path is searched in the
device's chart and inserted with its device commands *mirrored* to the controller's
side. The device's "wait for request Open" becomes the controller's "send request
Open"; the device's "send event gripper_closed" becomes the controller's "wait for
event gripper_closed". Synchronisation between regions (``In('...')``) is kept,
pointing at the controller states the general states became.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from plugnproduce.chartnames import STEP, VALUES
from plugnproduce.description.model import ChartTransition, Command, DeviceDescription, ProcessDescription, Role
from plugnproduce.description.paths import find_path
from plugnproduce.description.quantities.contracts import in_contract_unit
from plugnproduce.ontology.iris import concept_value, local_name
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.statechart.model import Final, Param, Send, State, Transition, pnp


@dataclass(frozen=True)
class Varying:
    """A parameter value that differs between the steps sharing a chart: read from the step's values."""

    name: str

    @property
    def expr(self) -> str:
        """The expression that reads it at run time."""
        return f"{VALUES}[{STEP}][{self.name!r}]"


@dataclass(frozen=True)
class Flow:
    """A parameter value taken from an earlier step's output: a variable of the task chart's datamodel."""

    variable: str
    offset: tuple[float, ...] | None = None
    """Added to the output item by item (a pose relative to the one reported)."""

    @property
    def expr(self) -> str:
        """The expression that reads it at run time (with the offset: each item plus its own)."""
        if self.offset is None:
            return self.variable
        return "[" + ", ".join(f"{self.variable}[{i}] + {o!r}" for i, o in enumerate(self.offset)) + "]"


@dataclass
class RegionResult:
    """One role's region of a Specific Process State Chart, bound to its device."""

    role: str
    device: DeviceDescription
    element: State
    start_state: str
    end_state: str
    commands: list[tuple[str, Command]] = field(default_factory=list)
    """(controller state id, command) in order: what the controller sends and waits for."""
    path: list[ChartTransition] = field(default_factory=list)
    """The transitions the device takes in its own chart, in order."""
    legs: list[int] = field(default_factory=list)
    """How many of :attr:`path`'s transitions each transition of the role's region takes, in order."""


def state_id(step: int, device: str, general_id: str, role: str) -> str:
    """Controller state id: step, device and the general state's name (``s2_gripper_open``)."""
    name = general_id[len(role) + 1 :] if general_id.startswith(role + "_") else general_id
    return f"s{step}_{device}_{name}".replace("-", "_")


def controller_ids(step: int, process: ProcessDescription, binding: dict[str, str]) -> dict[str, str]:
    """Every general state id of the process → the controller state it becomes in this step."""
    return {g.id: state_id(step, binding[r.name], g.id, r.name) for r in process.roles for g in r.region}


def specific_region(
    step: int,
    process: ProcessDescription,
    role: Role,
    device: DeviceDescription,
    start_state: str,
    params: dict[str, object],
    ids: dict[str, str],
    taxonomy: Taxonomy,
) -> RegionResult:
    """Build the controller's region for ``role`` played by ``device``, from the device state ``start_state``."""
    region = State(id=f"s{step}_{device.id}".replace("-", "_"), initial=[ids[role.region[0].id]],
                   extra_attrs={pnp("role"): role.name, pnp("device"): device.id})
    result = RegionResult(role.name, device, region, start_state, start_state)
    current = start_state
    head_kind = Final if len(role.region) == 1 else State  # a one-state role is done at once
    states: list[State | Final] = [head_kind(id=ids[role.region[0].id],
                                             extra_attrs=_annotation(role.region[0].concept, current))]
    for general in role.region[1:]:
        wanted = frozenset(process.parameter(p).quantity for p in general.params)
        path = find_path(device, current, general.concept, taxonomy, wanted)
        cond = f"In('{ids[general.waits_for]}')" if general.waits_for else None
        values = {p: params[p] for p in general.params if p in params}
        _insert_path(states, path.steps, ids[general.id], device, values, process, cond, result)
        result.path.extend(path.steps)
        result.legs.append(len(path.steps))
        current = path.target
        kind = Final if general is role.region[-1] else State
        states.append(kind(id=ids[general.id], extra_attrs=_annotation(general.concept, current)))
    region.children.extend(states)
    result.end_state = current
    return result


def _annotation(concept: str, device_state: str) -> dict[str, str]:
    return {pnp("concept"): concept_value(concept), pnp("deviceState"): device_state}


def _insert_path(
    states: list[State | Final],
    steps: tuple[ChartTransition, ...],
    target_id: str,
    device: DeviceDescription,
    values: dict[str, object],
    process: ProcessDescription,
    cond: str | None,
    result: RegionResult,
) -> None:
    """Append the mirrored transitions of a path, with the intermediate states it passes."""
    source = states[-1]
    assert isinstance(source, State)  # only the last region state is a <final>, and it is not appended yet
    if not steps:
        source.transitions.append(Transition(targets=[target_id], cond=cond))
        return
    for i, edge in enumerate(steps):
        last = i == len(steps) - 1
        moves: list[tuple[str, Command | None]] = []
        if edge.request:
            moves.append(("send", edge.request))
        moves += [("wait", c) for c in edge.sends]
        if not moves:
            moves.append(("pass", None))
        for j, (kind, command) in enumerate(moves):
            final_move = last and j == len(moves) - 1
            nxt = target_id if final_move else f"{target_id}_{i + 1}{'abcdefghij'[j]}"
            t = Transition(targets=[nxt], cond=cond if i == 0 and j == 0 else None)
            if kind == "send" and command is not None:
                t.actions.append(_request(device, command, edge.accepts, values, process))
                result.commands.append((source.id or "", command))
            elif kind == "wait" and command is not None:
                t.event = f"{device.id}.{command.event}"
                result.commands.append((source.id or "", command))
            source.transitions.append(t)
            if not final_move:
                source = State(id=nxt, extra_attrs={pnp("deviceState"): edge.target})
                states.append(source)


def _request(
    device: DeviceDescription,
    command: Command,
    accepts: tuple[str, ...],
    values: dict[str, object],
    process: ProcessDescription,
) -> Send:
    send = Send(type=command.protocol, target=device.id, event=command.event)
    given: set[str] = set()
    for name, value in sorted(values.items()):
        par = process.parameter(name)
        if par.quantity in accepts:
            contract = device.argument(command.name, par.quantity)
            expr = (value.expr if isinstance(value, Varying | Flow)
                    else literal(in_contract_unit(value, par.unit, contract)))
            send.params.append(Param(name=local_name(par.quantity), expr=expr))
            given.add(par.quantity)
    for quantity in accepts:  # an argument the process does not supply takes the device's own default
        contract = device.argument(command.name, quantity)
        if quantity not in given and contract.default is not None:
            send.params.append(Param(name=local_name(quantity), expr=literal(contract.default)))
    return send




def literal(value: object) -> str:
    """A Python-datamodel expression for a parameter value."""
    if isinstance(value, str) and not _is_pose(value):
        return repr(value)
    if isinstance(value, str):
        return "[" + ", ".join(value.split()) + "]"
    if isinstance(value, list):
        return "[" + ", ".join(format(float(v), "g") for v in value) + "]"
    return repr(value)


def _is_pose(value: str) -> bool:
    parts = value.split()
    try:
        return len(parts) == 6 and all(float(p) == float(p) for p in parts)
    except ValueError:
        return False

