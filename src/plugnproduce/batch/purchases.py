"""Minimal purchase: the cheapest sets of catalogue devices whose addition makes every task plausible.

Adding devices can only fill roles that nothing plays (``no_device``) and bring in devices a step
names (``absent``); every other finding of the configuration stays, so it is a proof that no
purchase helps. A useful set holds, for each role nothing plays, exactly one device that can play
it (two would make the binding ambiguous) and every named absent device; a device that fills none
of those roles is never needed (it is either unused or makes a binding ambiguous). Such sets are
enumerated cheapest first (cost, then fewest devices, then catalogue order) and checked with
:mod:`.feasibility`; the first ``top`` that make every task plausible are the answer. When the
enumeration is exhausted, no set from the catalogue suffices, and the answer says why.

A role several devices of the configuration can play (``ambiguous``) is no impossibility, and no
purchase cures it (a device added can only make it more ambiguous): the answer says which step's
role to bind, and to which devices, instead of offering purchases. A finding no binding or purchase
can cure (a bad value, a device's limits, a role no catalogue device plays) still makes it impossible.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from plugnproduce.batch.feasibility import Feasibility, Finding

LIMIT = 100_000
"""Candidate sets looked at per configuration before the search gives up (and says so)."""

KINDS = {
    "no_device": "no device can play role {role}",
    "ambiguous": "several devices can play role {role}",
    "absent": "device {device} named for role {role} is not in the cell",
    "cannot_play": "device {device} named for role {role} cannot play it",
    "unknown_role": "the process has no role {role}",
    "unknown_command": "no process has this name",
    "bad_value": "a parameter value does not fit its declaration",
    "wrong_state": "device {device} is not in the state role {role} starts from",
    "stuck": "device {device} cannot play role {role} from the state it is in",
    "not_accepted": "device {device} (role {role}) accepts no command for a parameter value given",
    "device_limit": "device {device} (role {role}) refuses a value sent to it by its own limits",
    "loop_fixpoint": "device {device} ends a loop iteration in another state than the iteration began in",
    "branch_join": "a branch leaves device {device} in another state than the other ways on from its step",
    "bad_link": "a value taken from an earlier step's output does not fit",
    "bad_flow": "a loop or branch cannot work as written",
}
"""The findings of a straight task; a task with loops, branches or links has those of the full check, which
``pnp check`` explains (:func:`describe` names their kind)."""


ON_THE_BINDING = frozenset({"wrong_state", "stuck", "loop_fixpoint", "branch_join"})
"""Findings of the states a task leaves its devices in: of a task with an ambiguous role, they are those of one
binding the check picked, and the answer is to bind the role (which may cure them)."""


@dataclass(frozen=True)
class Purchase:
    """The cheapest sets of devices to add, cheapest first, or why there is none."""

    options: tuple[tuple[tuple[str, ...], int], ...]
    """Each option: the devices to add (sorted) and their total cost."""
    impossible: str | None = None
    ambiguous: str | None = None
    """Which step's role several devices of the configuration can play, and to bind it (no purchase cures it)."""

    @property
    def outcome(self) -> str:
        """``buy`` (options to buy), ``ambiguous`` (bind a role first) or ``impossible``."""
        return "ambiguous" if self.ambiguous is not None else "impossible" if self.impossible is not None else "buy"

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        out: dict[str, object] = {"options": [{"add": list(a), "cost": k} for a, k in self.options]}
        if self.impossible is not None:
            out["impossible"] = self.impossible
        if self.ambiguous is not None:
            out["ambiguous"] = self.ambiguous
        return out

    def text(self) -> str:
        """One line: ``a+b=cost`` per option, ``ambiguous: what to bind`` or ``impossible: why``."""
        if self.ambiguous is not None:
            return f"ambiguous: {self.ambiguous}"
        if self.impossible is not None:
            return f"impossible: {self.impossible}"
        return " | ".join(f"{'+'.join(a)}={k}" for a, k in self.options)


def describe(feasibility: Feasibility, task: int, finding: Finding, mask: int | None = None) -> str:
    """A finding in words: ``step 2 of pick-and-place: no device can play role gripper``; with the
    configuration's ``mask``, a value a device's limits refuse is named with its parameter and the limit."""
    kind, step, role, device = finding
    name = feasibility.abilities.tasks[task].name
    text = KINDS.get(kind, f"a finding of kind {kind} (pnp check says why)").format(role=role, device=device)
    if kind == "device_limit" and mask is not None:
        text += f": {feasibility.limit(task, finding, mask)}"
    return f"step {step} of {name}: {text}"


def _ambiguity(feasibility: Feasibility, task: int, finding: Finding) -> str:
    """``step 2 of t: several devices can play role gripper; bind step 2's role gripper to one of them``.

    The devices are not named: the answer is shared by every configuration whose devices bind the task's roles
    alike (:meth:`.Feasibility.key`), and the configuration's own devices are beside it in the report."""
    _, step, role, _ = finding
    return f"{describe(feasibility, task, finding)}; bind step {step}'s role {role} to one of them"


def purchase(feasibility: Feasibility, mask: int, top: int = 1) -> Purchase | None:
    """The ``top`` cheapest purchases for a configuration; None when every task is already plausible."""
    ab = feasibility.abilities
    found = [feasibility.findings(t, mask) for t in range(len(ab.tasks))]
    if not any(found):
        return None
    groups: set[int] = set()
    forced = 0
    ambiguous = ""
    for t, findings in enumerate(found):
        if any(f[0] == "ambiguous" for f in findings):  # where it goes on from depends on the binding chosen
            findings = tuple(f for f in findings if f[0] not in ON_THE_BINDING)
        for f in findings:
            kind, step, role, device = f
            process = ab.tasks[t].steps[step - 1].process or ""
            if kind == "no_device":
                players = ab.players.get((process, role), 0) & ~mask
                if not players:
                    return Purchase((), f"{describe(feasibility, t, f)}, and no catalogue device can "
                                        f"(it needs skill {ab.skills[(process, role)]})")
                groups.add(players)
            elif kind == "absent" and ab.bit(device):
                forced |= ab.bit(device)
            elif kind == "ambiguous":
                ambiguous = ambiguous or _ambiguity(feasibility, t, f)
            else:
                return Purchase((), describe(feasibility, t, f, mask) + (
                    "; it is not in the catalogue" if kind == "absent" else "; adding devices cannot cure it"))
    if ambiguous:
        return Purchase((), ambiguous=ambiguous)
    return _search(feasibility, mask, sorted(groups), forced, top)


def _search(feasibility: Feasibility, mask: int, groups: list[int], forced: int, top: int) -> Purchase:
    ab = feasibility.abilities
    pool = 0
    for g in groups:
        pool |= g
    pool &= ~forced
    items = sorted((n for n in range(len(ab.devices)) if pool >> n & 1), key=lambda n: (ab.costs[n], n))
    base = sum(ab.costs[n] for n in range(len(ab.devices)) if forced >> n & 1)
    options: list[tuple[tuple[str, ...], int]] = []
    first_failure = ""
    heap: list[tuple[int, int, tuple[int, ...], int]] = [(base, 0, (), forced)]
    looked = 0
    while heap and len(options) < top and looked < LIMIT:
        cost, _, picked, chosen = heapq.heappop(heap)
        looked += 1
        if all((chosen & g).bit_count() == 1 for g in groups):
            failure = _failure(feasibility, mask | chosen)
            if failure is None:
                options.append((tuple(sorted(ab.devices[n] for n in range(len(ab.devices)) if chosen >> n & 1)),
                                cost))
            first_failure = first_failure or f"adding {_names(ab.devices, chosen)}: {failure}"
        _successors(heap, items, ab.costs, cost, picked, chosen, groups)
    if options:
        return Purchase(tuple(options))
    if heap:
        return Purchase((), f"no purchase found among the first {LIMIT} candidate sets (search stopped)")
    return Purchase((), "no set of catalogue devices makes every task plausible"
                    + (f"; e.g. {first_failure}" if first_failure else ""))


def _successors(heap: list[tuple[int, int, tuple[int, ...], int]], items: list[int], costs: tuple[int, ...],
                cost: int, picked: tuple[int, ...], chosen: int, groups: list[int]) -> None:
    """Push the subsets after ``picked`` in (cost, size, items) order: extend it, or move its last item on."""
    last = picked[-1] if picked else -1
    if last + 1 >= len(items):
        return
    nxt = items[last + 1]
    if all((chosen & g).bit_count() <= 1 for g in groups):  # a superset of an ambiguous set stays ambiguous
        heapq.heappush(heap, (cost + costs[nxt], len(picked) + 1, (*picked, last + 1), chosen | 1 << nxt))
    if picked:
        moved = chosen & ~(1 << items[last]) | 1 << nxt
        heapq.heappush(heap, (cost - costs[items[last]] + costs[nxt], len(picked), (*picked[:-1], last + 1), moved))


def _failure(feasibility: Feasibility, mask: int) -> str | None:
    for t in range(len(feasibility.abilities.tasks)):
        findings = feasibility.findings(t, mask)
        if findings:
            return describe(feasibility, t, findings[0], mask)
    return None


def _names(devices: tuple[str, ...], mask: int) -> str:
    return "+".join(d for n, d in enumerate(devices) if mask >> n & 1)
