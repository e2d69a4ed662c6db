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

from plugnproduce.description.model import DeviceDescription, Parameter, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning import schema as s
from plugnproduce.reasoning.accepts import accepts
from plugnproduce.reasoning.contracts import refuses, why_refused
from plugnproduce.reasoning.terms import Atom


class _Terms:
    """The answers of :func:`refuses` and :func:`accepts` for the devices with the skill a parameter's role needs
    (no other device can be bound to it), each asked once per parameter and value."""

    def __init__(self, devices: Sequence[DeviceDescription], taxonomy: Taxonomy) -> None:
        self.devices = tuple({d.id: d for d in devices}.values())
        self.taxonomy = taxonomy
        self._players: dict[str, tuple[DeviceDescription, ...]] = {}
        self._refusing: dict[tuple[str, str], tuple[str, ...]] = {}
        self._deaf: dict[str, tuple[str, ...]] = {}

    def players(self, proc: ProcessDescription, par: Parameter) -> tuple[DeviceDescription, ...]:
        """The devices that have the skill the role of ``par`` requires."""
        if par.iri not in self._players:
            role = next((r for r in proc.roles if r.name == par.role), None)
            self._players[par.iri] = tuple(d for d in self.devices if role is not None
                                           and any(self.taxonomy.is_a(k, role.required_skill) for k in d.skills))
        return self._players[par.iri]

    def refusing(self, proc: ProcessDescription, par: Parameter, value: object) -> tuple[str, ...]:
        """The devices that could play the role of ``par`` and refuse ``value`` by their own limits."""
        key = (par.iri, repr(value))
        if key not in self._refusing:
            self._refusing[key] = tuple(d.id for d in self.players(proc, par) if refuses(d, value, par))
        return self._refusing[key]

    def deaf(self, proc: ProcessDescription, par: Parameter) -> tuple[str, ...]:
        """The devices that could play the role of ``par`` and none of whose requests accepts its quantity."""
        if par.iri not in self._deaf:
            self._deaf[par.iri] = tuple(d.id for d in self.players(proc, par)
                                        if not accepts(d, par.quantity, self.taxonomy))
        return self._deaf[par.iri]


def refusal_facts(task: Task, name: str, devices: Sequence[DeviceDescription],
                  processes: Sequence[ProcessDescription], taxonomy: Taxonomy) -> list[Atom]:
    """``value_refused/4`` for each step's values (``task`` with its quantities in their parameters' units) and
    ``default_refused/3`` for each parameter's default, over ``devices`` (the cell's and the catalogue's)."""
    terms = _Terms(devices, taxonomy)
    out: list[Atom] = []
    for proc in processes:
        for par in proc.parameters:
            if par.default is not None:
                out += [s.DefaultRefused(proc.id, par.name, d) for d in terms.refusing(proc, par, par.default)]
    by_id = {p.id: p for p in processes}
    for step in task.steps:
        command = by_id.get(step.command)
        if command is None:
            continue
        for par in command.parameters:
            value = step.params.get(par.name, par.default)
            refusing = set(terms.refusing(command, par, value)) if value is not None else set()
            if par.name in step.params:
                refusing.update(terms.deaf(command, par))
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
