"""A task's values against the units of its processes and the limits of the devices bound to them.

Two steps of the plausibility check:

- :func:`normalised` reads each quantity a task writes with a unit (``"0.12 kN"``) in the unit
  its process parameter declares (``120`` N); a unit of another dimension or an unknown unit is a
  problem at the value's line, and a number that is not finite, as written or once converted
  (``1e308 kN``), is bad input there (:class:`~plugnproduce.errors.QuantityError`);
- :func:`beyond_limits` holds each value a device is sent (given, or the process's default) to
  that device's contract for the request that carries it (``pnp:RequestArgument``): its minimum
  and maximum, in the device's unit, and for a pose the device's reach.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING

from plugnproduce.description.model import (
    Argument,
    Cell,
    DeviceDescription,
    Parameter,
    ProcessDescription,
    Task,
    Where,
)
from plugnproduce.description.quantities.contracts import breach
from plugnproduce.description.quantities.units import Amount, UnitError, convert, read_amount
from plugnproduce.errors import QuantityError, excerpt
from plugnproduce.reasoning.asp.facts import DATATYPES
from plugnproduce.reasoning.asp.results import Problem, Reason, StepCheck

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

NUMERIC = ("decimal", "integer")


def _numeric(par: Parameter) -> bool:
    return DATATYPES.get(par.datatype, par.datatype) in NUMERIC


def normalised(task: Task, processes: Sequence[ProcessDescription],
               keep_unreadable: bool = False) -> tuple[Task, list[Problem]]:
    """The task with every quantity written with a unit in its parameter's unit, and the values that cannot be.

    A value that cannot be read is left out of the task returned (its parameter takes the default
    there), so that one problem, not two, is told of it; with ``keep_unreadable`` it stays as written
    (the repair then sees a value that does not fit, and resets it).
    """
    declared = {p.id: {x.name: x for x in p.parameters} for p in processes}
    one_round = len(task.one_round())
    steps, problems = [], []
    for step in task.steps:
        params = dict(step.params)
        for name, value in step.params.items():
            par = declared.get(step.command, {}).get(name)
            amount = read_amount(value) if isinstance(value, str) else None
            if par is None or amount is None or not _numeric(par):
                continue  # not a quantity written as text: the type check tells of anything wrong with it
            number, why = _read(amount, par)
            if not math.isfinite(number) and why is None or not math.isfinite(amount.number):
                raise QuantityError(_not_finite(step.index, step.command, name, value, amount, par),
                                    *_at(task.where(step, name)))
            if why is None:
                params[name] = int(number) if par.datatype.endswith("integer") and number.is_integer() else number
                continue
            if not keep_unreadable:
                del params[name]
            if step.index <= one_round:
                text = f"step {step.index} ({step.command}): parameter {name} is {value!r}; {why}"
                problems.append(Problem(step.index, step.command, "bad_unit", Reason("bad_unit", text, (par.quantity,),
                                        (par.where,)), task.where(step, name), role=par.role, parameter=name))
        steps.append(step if params == step.params else dataclasses.replace(step, params=params))  # most: as read
    return dataclasses.replace(task, steps=tuple(steps)), problems


def _not_finite(index: int, command: str, name: str, value: object, amount: Amount, par: Parameter) -> str:
    what = f"step {index} ({command}): parameter {name} is {excerpt(str(value))!r}"
    if not math.isfinite(amount.number):
        return f"{what}; expected a finite number"
    return f"{what}, which in {par.unit} is beyond any number a device can be given; expected a finite quantity"


def _at(where: Where) -> tuple[str, int | None]:
    return where.file, where.line


def _read(amount: Amount, par: Parameter) -> tuple[float, str | None]:
    """An amount in the parameter's unit, or why it cannot be read so."""
    if amount.unit and not par.unit:
        return math.nan, f"parameter {par.name} takes a plain number (no unit)"
    try:
        return convert(amount.number, amount.unit, par.unit), None
    except UnitError as exc:
        return math.nan, f"expected a quantity in {par.unit} or a unit convertible to it ({exc})"


# ------------------------------------------------------------------ the devices' limits


def contracts_for(device: DeviceDescription, quantity: str) -> list[Argument]:
    """The contracts of the device's requests that carry ``quantity`` (one per request)."""
    requests = sorted({t.request.name for t in device.transitions if t.request and quantity in t.accepts})
    return [device.argument(r, quantity) for r in requests]


def beyond_limits(task: Task, cell: Cell, steps: tuple[StepCheck, ...], knowledge: Knowledge) -> Iterator[Problem]:
    """One problem per value (given or default) outside the limits of the device it goes to."""
    devices = {d.id: d for d in cell.devices}
    procs = knowledge.processes_by_id
    for check, step in zip(steps, task.one_round(), strict=False):
        proc = procs.get(step.command)
        for par in proc.parameters if proc else ():
            device = devices.get(check.bindings.get(par.role, ""))
            value = step.params.get(par.name, par.default)
            if device is None or value is None or _beyond_own_range(value, par):
                continue  # the type and range check tells of a value outside the process's own range
            for contract in contracts_for(device, par.quantity):  # as refuses(), telling why
                why = _beyond(value, par, contract)
                if why is None:
                    continue
                text = (f"step {step.index} ({step.command}): {sent(par, value, par.name in step.params)} goes to "
                        f"device '{device.id}' with request {contract.request}, which {why}")
                rests = tuple(w for w in (contract.where, par.where) if w is not None) or (device.where,)
                reason = Reason("device_limit", text, (par.quantity, device.iri), rests)
                yield Problem(step.index, step.command, "device_limit", reason, task.where(step, par.name),
                              role=par.role, device=device.id, parameter=par.name)


def refuses(device: DeviceDescription, value: object, par: Parameter) -> bool:
    """Whether ``device`` refuses ``value`` of ``par`` by its own limits (what :func:`beyond_limits` tells of)."""
    return why_refused(device, value, par) is not None


def why_refused(device: DeviceDescription, value: object, par: Parameter) -> str | None:
    """Why ``device`` refuses ``value`` of ``par`` by its own limits ("takes at least 20 kPa; the value is 15 kPa"),
    or None when it takes it (or when the value is beyond the process's own range: the range check tells of it)."""
    if _beyond_own_range(value, par):
        return None
    return next((why for contract in contracts_for(device, par.quantity)
                 if (why := _beyond(value, par, contract)) is not None), None)


def refusal(device: DeviceDescription, value: object, par: Parameter, given: bool) -> str | None:
    """Why ``device`` refuses ``value`` of ``par`` (``given`` by the step, else its default) by its own limits,
    naming the value and the request (None when it takes it): ``parameter grip_force = 150 goes with request
    Close, which takes at most 140 N; the value is 150 N``."""
    if _beyond_own_range(value, par):
        return None
    for contract in contracts_for(device, par.quantity):
        why = _beyond(value, par, contract)
        if why is not None:
            return f"{sent(par, value, given)} goes with request {contract.request}, which {why}"
    return None


def sent(par: Parameter, value: object, given: bool) -> str:
    """A parameter and its value as sent: ``parameter place_pose (its default) = [0.9, 0.5, 0.1, 0, 180, 0]``."""
    shown = repr(value) if isinstance(value, str) else str(list(value)) if isinstance(value, tuple) else str(value)
    if len(shown) > 60:
        shown = shown[:57] + "..."
    unit = f" {par.unit}" if par.unit and isinstance(value, int | float) and not isinstance(value, bool) else ""
    return f"parameter {par.name}{'' if given else ' (its default)'} = {shown}{unit}"


def _beyond_own_range(value: object, par: Parameter) -> bool:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    return ((par.minimum is not None and value < par.minimum)
            or (par.maximum is not None and value > par.maximum))


def _beyond(value: object, par: Parameter, contract: Argument) -> str | None:
    """Why ``value`` (in the parameter's unit) breaks the device's contract, or None if it keeps it
    (the one definition, :func:`plugnproduce.description.quantities.contracts.breach`). A number the process
    takes is held to the device's own datatype too, as the executor holds it (a whole number for an
    ``xsd:integer`` argument: 45.5 N never goes to a gripper that takes whole newtons); a value of the wrong
    type for the process itself is the type check's to tell of."""
    number = _numeric(par) and isinstance(value, int | float) and not isinstance(value, bool)
    return breach(value, par.unit, contract, types=number)
