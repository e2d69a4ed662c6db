"""Counterfactuals: the smallest changes that turn a "no" into a "yes" (a device to add or swap in, a state a
device would have to be in), and for a "yes" the single fact whose removal turns it into a "no". Each one is
confirmed by running the reasoner again with the change made; none is offered unconfirmed."""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.description.paths import in_concept
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.facts import FactBook, fact_book
from plugnproduce.reasoning.asp.results import CheckResult
from plugnproduce.reasoning.checks.offers import CELL, cell_program
from plugnproduce.reasoning.checks.plausibility import check
from plugnproduce.reasoning.repairs.sideeffects import AssessedRepair

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

MAX_PAIRS = 400
"""At most this many pairs of catalogue devices are tried when no single device makes a process offered."""


@dataclass(frozen=True)
class Counterfactual:
    """One change, and what the reasoner answers once it is made."""

    kind: str
    """``add_device``, ``swap_device``, ``remove_device``, ``state`` or ``edit_task`` (a repair: steps to insert,
    remove or reorder)."""
    text: str
    confirmed: bool
    """The reasoner, run again with the change, gives the opposite answer."""
    devices: tuple[str, ...] = ()
    """The devices the change adds (add, swap), removes (remove) or puts in a state (state)."""
    replaces: str | None = None
    """Swap: the device of the cell it replaces."""
    state: str | None = None
    step: int | None = None
    loses: tuple[str, ...] = ()
    """Process commands the cell offers now and would no longer offer after the change."""
    side_effects: tuple[str, ...] = ()
    """What else the change does (a repair's side effects)."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(self).items()
                if v not in (None, ())}


def offered(book: FactBook, cell: Cell) -> frozenset[str]:
    """The process commands ``cell`` offers (offered.lp alone: no reasons, no bindings)."""
    model = solver.solve(solver.OFFERED, cell_program(book, cell))
    return frozenset(a.p for a in model[s.Offered] if a.c == CELL)


def _with(cell: Cell, add: Sequence[DeviceDescription], drop: str | None = None) -> Cell:
    return dataclasses.replace(cell, devices=tuple(d for d in cell.devices if d.id != drop) + tuple(add))


def _names(devices: Sequence[DeviceDescription]) -> str:
    return " and ".join(f"'{d.id}' ({d.label})" for d in devices)


def make_offered(command: str, cell: Cell, catalogue: Sequence[DeviceDescription],
                 knowledge: Knowledge) -> list[Counterfactual]:
    """Catalogue devices to add (one, else two) or swap in for one of the cell's that make ``command`` offered."""
    book = fact_book(knowledge)
    now = offered(book, cell)
    present = {d.id for d in cell.devices}
    spare = [d for d in catalogue if d.id not in present]
    out: list[Counterfactual] = []
    for dev in spare:
        if command in offered(book, _with(cell, [dev])):
            out.append(Counterfactual("add_device", f"add device {_names([dev])} to the cell", True, (dev.id,)))
    for old, dev in itertools.product(cell.devices, spare):
        after = offered(book, _with(cell, [dev], old.id))
        if command in after:
            lost = tuple(sorted(now - after))
            text = f"replace device '{old.id}' with {_names([dev])}"
            text += f" (the cell would no longer offer {', '.join(lost)})" if lost else ""
            out.append(Counterfactual("swap_device", text, True, (dev.id,), old.id, loses=lost))
    added = any(c.kind == "add_device" for c in out)
    out = [c for c in out if not (added and c.loses)]  # a swap that costs other commands only when nothing else
    if not added:
        for pair in itertools.islice(itertools.combinations(spare, 2), MAX_PAIRS):
            if command in offered(book, _with(cell, list(pair))):
                out.append(Counterfactual("add_device", f"add devices {_names(pair)} to the cell", True,
                                          tuple(d.id for d in pair)))
    return sorted(out, key=lambda c: (len(c.devices), c.kind != "add_device", len(c.loses), c.text))


def make_not_offered(command: str, cell: Cell, knowledge: Knowledge) -> list[Counterfactual]:
    """The single devices of the cell without which ``command`` would not be offered (why these devices)."""
    book = fact_book(knowledge)
    out = []
    for dev in cell.devices:
        if command not in offered(book, _with(cell, [], dev.id)):
            out.append(Counterfactual("remove_device", f"without device '{dev.id}' ({dev.label}) the cell would "
                                                       f"not offer {command}", True, (dev.id,)))
    return out


def _from_states(cell: Cell, states: dict[str, str]) -> Cell:
    """The cell with each device starting in the given chart state (planning from where the devices are)."""
    return dataclasses.replace(cell, devices=tuple(dataclasses.replace(d, initial=states.get(d.id, d.initial))
                                                   for d in cell.devices))


def needed_states(result: CheckResult, task: Task, n: int, cell: Cell, knowledge: Knowledge) -> list[Counterfactual]:
    """For a step that is not plausible: the chart states its devices would have to be in when it starts, each
    confirmed by checking the step alone from the states the devices are in then, with that one changed."""
    step = result.steps[n - 1]
    alone = dataclasses.replace(task, steps=(dataclasses.replace(task.steps[n - 1], index=1),), loops=(), branches=(),
                                repeat=1)
    out: list[Counterfactual] = []
    for p in result.problems:
        if p.step != n or p.kind != "wrong_state" or p.device is None or p.needed is None:
            continue
        dev = next(d for d in cell.devices if d.id == p.device)
        for st in dev.states:
            if not in_concept(st, p.needed, knowledge.taxonomy):
                continue
            states = {**step.states, p.device: st.id}
            ok = check(alone, _from_states(cell, states), knowledge).plausible
            if ok:
                label = knowledge.taxonomy.label(st.concept or p.needed)
                out.append(Counterfactual("state", f"if device '{p.device}' were in state '{st.id}' ({label}) when "
                                                   f"step {n} starts, the step would be plausible", True,
                                          (p.device,), state=st.id, step=n))
    return out


def from_repairs(repairs: Sequence[AssessedRepair]) -> list[Counterfactual]:
    """Repairs as counterfactuals of a step that is not plausible: the edits, confirmed when checking the repaired
    task again finds it plausible, with their side effects, in the repairs' rank."""
    return [Counterfactual("edit_task", "; ".join(e.text for e in r.repair.edits), r.confirmed,
                           r.repair.added_devices, side_effects=tuple(e.text for e in r.side_effects))
            for r in repairs]
