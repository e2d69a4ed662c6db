"""What depends on the combination of devices: offered processes and task plausibility of one configuration.

A configuration is a bit mask over the catalogue (:class:`.abilities.Abilities`). The rules are
those of ``offered.lp``, ``resolve.lp`` and ``chain.lp``, applied to the per-device tables:

- a process is offered when each of its roles has a device of the configuration that can play it;
- a role a step names a device for is played by that device (``absent`` if it is not plugged in,
  ``cannot_play`` if it cannot); another role is played by the one device that can play it
  (``no_device`` when there is none, ``ambiguous`` when there are several);
- when every role of every process a step names is bound, the chain runs (past a step of no process, which
  moves no device, and a role the process does not have, as check's chain does): each device starts in its initial
  states, a step needs each bound device in a state its role's start concept subsumes
  (``wrong_state``) from which the role can be played (``stuck``), and leaves it where the role
  ends; a device filling several roles of a step plays them in role order;
- a parameter value given to a bound device none of whose commands accepts its quantity is
  ``not_accepted`` (accepts.py); a value sent to a bound device (given or the default) beyond
  that device's own limits is ``device_limit`` (contracts.py).

A task with loops, branches or data links is answered by the full check instead (every path, every loop
iteration, every link; :class:`.abilities.FullCheck`), once per key as below.

A task's answer depends only on, for each role it leaves to the configuration, whether none, one
(which) or several of the devices that can play it are present, and on whether each device it
names is present: answers are remembered by that key, and offered processes by the set of roles
the configuration's devices can fill (bounded: a memory is cleared when full).
"""

from __future__ import annotations

from collections import defaultdict

from plugnproduce.reasoning.checks.abilities import Abilities, TaskSpec

Finding = tuple[str, int, str, str]
"""Why a task is not plausible: (kind, step, role, device); role and device are "" where they do not apply."""

MEMORY = 1 << 16
"""Answers remembered per task (and offered-process sets) before that memory is cleared."""

Key = tuple[int, ...]


class Feasibility:
    """Offered processes and task findings of configurations over one :class:`Abilities`."""

    def __init__(self, abilities: Abilities) -> None:
        self.abilities = abilities
        index = {pr: n for n, pr in enumerate(sorted(abilities.players))}
        self._fills = tuple(sum(1 << index[pr] for pr, m in abilities.players.items() if m >> d & 1)
                            for d in range(len(abilities.devices)))
        self._needs = tuple((p, sum(1 << index[(p, r)] for r in roles))
                            for p, roles in abilities.processes if all((p, r) in index for r in roles))
        self._offered: dict[int, tuple[str, ...]] = {}
        self._keys = tuple(_key_masks(abilities, t) for t in abilities.tasks)
        self._all = tuple(sorted(set().union(*self._keys)))
        self._memo: list[dict[Key, tuple[Finding, ...]]] = [{} for _ in abilities.tasks]

    def fill(self, mask: int) -> int:
        """The roles (a bit each) the devices of a configuration can fill: what :meth:`offered` depends on."""
        fill = 0
        while mask:
            low = mask & -mask
            fill |= self._fills[low.bit_length() - 1]
            mask ^= low
        return fill

    def offered(self, mask: int, fill: int | None = None) -> tuple[str, ...]:
        """The processes a configuration offers, sorted; ``fill``: its :meth:`fill` if already known."""
        fill = self.fill(mask) if fill is None else fill
        found = self._offered.get(fill)
        if found is None:
            if len(self._offered) >= MEMORY:
                self._offered.clear()
            found = self._offered[fill] = tuple(p for p, need in self._needs if fill & need == need)
        return found

    def key_all(self, mask: int) -> Key:
        """What every task's answer depends on (the :meth:`key` of each, at once): per role any task leaves to
        the configuration, the one present player, 0 or -1 (several); per device a task names, its bit or 0."""
        return tuple(x if not x & (x - 1) else -1 for x in (mask & m for m in self._all))

    def key(self, task: int, mask: int) -> Key:
        """What task number ``task``'s answer depends on: per role the one present player, 0 or -1 (several)."""
        return tuple(x if not x & (x - 1) else -1 for x in (mask & m for m in self._keys[task]))

    def findings(self, task: int, mask: int, key: Key | None = None) -> tuple[Finding, ...]:
        """Why task number ``task`` is not plausible in a configuration (empty: it is plausible);
        ``key``: its :meth:`key` if already known."""
        key = key if key is not None else self.key(task, mask)
        memo = self._memo[task]
        found = memo.get(key)
        if found is None:
            if len(memo) >= MEMORY:
                memo.clear()
            found = memo[key] = _findings(self.abilities, self.abilities.tasks[task], mask)
        return found

    def limit(self, task: int, finding: Finding, mask: int) -> str:
        """Why the device of a ``device_limit`` finding refuses a value: the parameter, its value and the
        request's limit (for a task with loops, branches or links, as the full check says it)."""
        _, index, role, device = finding
        spec = self.abilities.tasks[task]
        if spec.flow is not None:
            return self.abilities.full.limit(spec.flow, mask, finding)
        d = self.abilities.devices.index(device)
        return "; ".join(why for r, k, why in spec.steps[index - 1].limits if r == role and k == d)

    def plausible(self, mask: int) -> tuple[str, ...]:
        """The tasks plausible in a configuration, in task order."""
        return tuple(t.name for n, t in enumerate(self.abilities.tasks) if not self.findings(n, mask))


def _key_masks(ab: Abilities, task: TaskSpec) -> tuple[int, ...]:
    """The player masks of the roles a task leaves to the configuration, and the bits of the devices it names."""
    out: set[int] = set()
    for step in task.steps:
        for role, named in step.roles:
            out.add(ab.bit(named) if named is not None else ab.players.get((step.process or "", role), 0))
    return tuple(sorted(out))


Binding = tuple[tuple[str, int], ...]
"""The (role, device index) pairs of one step, in role order."""


def _findings(ab: Abilities, task: TaskSpec, mask: int) -> tuple[Finding, ...]:
    if task.flow is not None:
        return ab.full.findings(task.flow, mask)
    out: list[Finding] = []
    unbound = False
    bindings: list[Binding] = []
    for step in task.steps:
        if step.bad_value:
            out.append(("bad_value", step.index, "", ""))
        if step.process is None:  # a step of no process moves no device: the chain goes on past it, as check's
            out.append(("unknown_command", step.index, "", ""))
            bindings.append(())
            continue
        out += [("unknown_role", step.index, r, "") for r in step.unknown_roles]
        bound, problems = _bind(ab, step.process, step.roles, step.index, mask)
        out += problems
        unbound |= bool(problems)
        played = dict(bound)
        out += [("not_accepted", step.index, role, ab.devices[played[role]]) for role, refusing in step.refusals
                if role in played and refusing >> played[role] & 1]
        out += [("device_limit", step.index, role, ab.devices[played[role]]) for role, refusing in step.beyond
                if role in played and refusing >> played[role] & 1]
        bindings.append(bound)
    if not unbound:
        out += _chain(ab, task, bindings)
    return tuple(sorted(set(out), key=lambda f: (f[1], f)))


def _bind(ab: Abilities, process: str, roles: tuple[tuple[str, str | None], ...], index: int,
          mask: int) -> tuple[Binding, list[Finding]]:
    bound: list[tuple[str, int]] = []
    problems: list[Finding] = []
    for role, named in roles:
        players = ab.players.get((process, role), 0)
        if named is not None:
            bit = ab.bit(named)
            if not mask & bit:
                problems.append(("absent", index, role, named))
            elif not players & bit:
                problems.append(("cannot_play", index, role, named))
            else:
                bound.append((role, bit.bit_length() - 1))
            continue
        found = mask & players
        if not found:
            problems.append(("no_device", index, role, ""))
        elif found & (found - 1):
            problems.append(("ambiguous", index, role, ""))
        else:
            bound.append((role, found.bit_length() - 1))
    return tuple(bound), problems


def _chain(ab: Abilities, task: TaskSpec, bindings: list[Binding]) -> list[Finding]:
    out: list[Finding] = []
    at: dict[int, frozenset[str]] = {}
    for step, binding in zip(task.steps, bindings, strict=True):
        process = step.process or ""
        roles_of: dict[int, list[str]] = defaultdict(list)
        for role, d in binding:
            roles_of[d].append(role)
        for d, roles in roles_of.items():
            states = at.get(d, ab.initial[d])
            for role in roles:
                states = _play(ab, process, role, d, states, step.index, out)
            at[d] = states
    return out


def _play(ab: Abilities, process: str, role: str, d: int, states: frozenset[str], index: int,
          out: list[Finding]) -> frozenset[str]:
    """Device ``d`` plays ``role`` from any of ``states``: record wrong starts, return where it ends."""
    start = ab.first.get((process, role))
    leaves = ab.leaves.get((process, role, d), {})
    after: set[str] = set()
    for x in states:
        if start is not None and start not in ab.concepts[d].get(x, ()):
            out.append(("wrong_state", index, role, ab.devices[d]))
        elif start is not None and x not in leaves:
            out.append(("stuck", index, role, ab.devices[d]))
        after |= leaves[x] if x in leaves else ab.recovers.get((process, role, d), frozenset())
    return frozenset(after)
