"""What the repair knows of the devices' own terms: the values each device would refuse (repair.lp).

The plausibility check holds every value a device is sent to that device's contract
(:mod:`.contracts`: its limits and reach) and refuses a given value no request of the bound
device accepts (:mod:`.accepts`). The repair must propose only what that check then confirms,
including for a device it buys from the catalogue: so it is told, for each step, which devices
(of the cell and of the catalogue) refuse the value the step sends for each parameter, and which
refuse a parameter's default. repair.lp then binds such a step to a device that takes its values,
or resets the refused value to its process's default where the device takes that (an edit with
its cost, whose text says which limit the value broke).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription, Parameter, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.terms import Atom
from plugnproduce.reasoning.checks.accepts import accepts
from plugnproduce.reasoning.checks.contracts import refuses, why_refused

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge


class Refusals:
    """The answers of :func:`refuses` and :func:`accepts` for one repair: each asked once per device, parameter
    and value (a device is known by its id: within one repair, the same id is the same device), and only of the
    devices with the skill a parameter's role needs (no other device can be bound to it)."""

    def __init__(self, taxonomy: Taxonomy) -> None:
        self.taxonomy = taxonomy
        self._plays: dict[tuple[str, str], bool] = {}
        self._refuses: dict[tuple[str, str, str], bool] = {}
        self._deaf: dict[tuple[str, str], bool] = {}
        self._defaults: dict[tuple[str, ...], list[Atom]] = {}

    def _players(self, devices: Sequence[DeviceDescription], proc: ProcessDescription,
                 par: Parameter) -> list[DeviceDescription]:
        role = next((r for r in proc.roles if r.name == par.role), None)
        out = []
        for d in devices:
            key = (d.id, par.iri)
            if key not in self._plays:
                self._plays[key] = role is not None and any(self.taxonomy.is_a(k, role.required_skill)
                                                            for k in d.skills)
            if self._plays[key]:
                out.append(d)
        return out

    def refusing(self, devices: Sequence[DeviceDescription], proc: ProcessDescription, par: Parameter,
                 value: object) -> list[str]:
        """The devices that could play the role of ``par`` and refuse ``value`` by their own limits."""
        out = []
        for d in self._players(devices, proc, par):
            key = (d.id, par.iri, repr(value))
            if key not in self._refuses:
                self._refuses[key] = refuses(d, value, par)
            if self._refuses[key]:
                out.append(d.id)
        return out

    def deaf(self, devices: Sequence[DeviceDescription], proc: ProcessDescription, par: Parameter) -> list[str]:
        """The devices that could play the role of ``par`` and none of whose requests accepts its quantity."""
        out = []
        for d in self._players(devices, proc, par):
            key = (d.id, par.iri)
            if key not in self._deaf:
                self._deaf[key] = not accepts(d, par.quantity, self.taxonomy)
            if self._deaf[key]:
                out.append(d.id)
        return out

    def defaults(self, devices: Sequence[DeviceDescription], processes: Sequence[ProcessDescription]) -> list[Atom]:
        """``default_refused/3`` of every parameter's default over ``devices``."""
        key = tuple(sorted({d.id for d in devices}))
        if key not in self._defaults:
            self._defaults[key] = [s.DefaultRefused(proc.id, par.name, d) for proc in processes
                                   for par in proc.parameters if par.default is not None
                                   for d in self.refusing(devices, proc, par, par.default)]
        return self._defaults[key]


def refusal_facts(task: Task, name: str, devices: Sequence[DeviceDescription], knowledge: Knowledge,
                  known: Refusals | None = None) -> list[Atom]:
    """``value_refused/4`` for each step's values (``task`` with its quantities in their parameters' units) and
    ``default_refused/3`` for each parameter's default, over ``devices`` (the cell's and the catalogue's);
    ``known``: the answers found so far in the same repair."""
    known = known or Refusals(knowledge.taxonomy)
    devices = list({d.id: d for d in devices}.values())
    out = list(known.defaults(devices, knowledge.processes))
    for step in task.steps:
        command = knowledge.processes_by_id.get(step.command)
        if command is None:
            continue
        for par in command.parameters:
            value = step.params.get(par.name, par.default)
            refusing = set(known.refusing(devices, command, par, value)) if value is not None else set()
            if par.name in step.params:
                refusing.update(known.deaf(devices, command, par))
            out += [s.ValueRefused(name, step.index, par.name, d) for d in sorted(refusing)]
    return out


def reset_reason(device: DeviceDescription | None, value: object, par: Parameter, taxonomy: Taxonomy) -> str:
    """Why a repair resets ``value`` of ``par`` sent to ``device``: the device's limit it breaks, or that no
    request of its chart takes it ("" when the device takes it: the value broke the process's own range)."""
    if device is None:
        return ""
    if not accepts(device, par.quantity, taxonomy):
        return f"no request of device '{device.id}' takes {taxonomy.label(par.quantity)}"
    why = why_refused(device, value, par)
    return f"device '{device.id}' {why}" if why else ""
