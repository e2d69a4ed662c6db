"""Offered process commands of a cell, role bindings, why-not answers (offered.lp, bindings.lp, explain.lp)."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task
from plugnproduce.errors import UnknownName
from plugnproduce.reasoning.asp import render, solver
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import FactBook, config_facts, fact_book
from plugnproduce.reasoning.asp.results import Capabilities, NotOffered, Offer, ProcessExplanation, Reason
from plugnproduce.reasoning.asp.terms import Model, program, strings

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

CELL = "cell"
"""The configuration name a single cell gets in ASP."""


def cell_program(book: FactBook, cell: Cell, extra: Sequence[DeviceDescription] = ()) -> str:
    """Facts of the processes, the cell's devices (and ``extra`` devices not in the cell) and its membership."""
    return (book.process_text() + book.devices_text([*cell.devices, *extra])
            + program(config_facts(CELL, [d.id for d in cell.devices])))


def context(book: FactBook, cell: Cell, extra: Sequence[DeviceDescription] = (),
            task: Task | None = None) -> render.Context:
    """The rendering context of a cell (and a task)."""
    devices = {d.id: d for d in [*extra, *cell.devices]}
    return render.Context(book.taxonomy, book.knowledge.processes_by_id, devices, cell.name, task)


def _bindings(model: Model, processes: Mapping[str, ProcessDescription]) -> dict[str, list[dict[str, str]]]:
    out: dict[str, list[dict[str, str]]] = defaultdict(list)
    for b in model[s.Binding]:
        roles = [r.name for r in processes[b.p].roles]
        devices = list(reversed(strings(b.devices)))
        out[b.p].append(dict(zip(roles, devices, strict=True)))
    for v in out.values():
        v.sort(key=lambda b: sorted(b.items()))
    return out


def role_players(model: Model, processes: Sequence[ProcessDescription]) -> dict[str, dict[str, tuple[str, ...]]]:
    """Per process, per role (in role order), the devices of the configuration that can fill it, sorted."""
    found: dict[tuple[str, str], set[str]] = defaultdict(set)
    for a in model[s.CanPlay]:
        found[(a.p, a.r)].add(a.d)
    return {p.id: {r.name: tuple(sorted(found[(p.id, r.name)])) for r in p.roles} for p in processes}


def binding_count(players: dict[str, tuple[str, ...]]) -> int:
    """How many valid role bindings there are: roles may share a device, so any player per role will do."""
    return math.prod(len(ds) for ds in players.values())


def witness(players: dict[str, tuple[str, ...]]) -> dict[str, str]:
    """The first valid binding in the order all bindings are listed: each role's first player."""
    return {r: ds[0] for r, ds in players.items()}


def _reasons(model: Model, ctx: render.Context) -> dict[str, list[Reason]]:
    out: dict[str, list[Reason]] = defaultdict(list)
    for a in sorted(model[s.NoSkill], key=lambda a: (a.p, a.r)):
        out[a.p].append(render.no_skill(ctx, a))
    for b in sorted(model[s.LacksState], key=lambda a: (a.p, a.r, a.d, a.i)):
        out[b.p].append(render.lacks_state(ctx, b))
    for c in sorted(model[s.Unreachable], key=lambda a: (a.p, a.r, a.d, a.i, a.x)):
        out[c.p].append(render.unreachable(ctx, c))
    for n in sorted(model[s.NoArgument], key=lambda a: (a.p, a.r, a.d, a.req, a.q)):
        out[n.p].append(render.no_argument(ctx, n))
    return out


def capabilities(cell: Cell, knowledge: Knowledge, all_bindings: bool = False) -> Capabilities:
    """What ``cell`` can do: offered commands, each with the devices that can fill each role, how many
    valid role bindings that makes and one of them (every one if ``all_bindings``); the others with reasons.

    Roles may share a device (roles.lp), so the bindings are every choice of one player per role:
    their number is a product, and only ``all_bindings`` lists them (bindings.lp)."""
    book = fact_book(knowledge)
    model = solver.solve(solver.BINDINGS if all_bindings else solver.CAPABILITIES, cell_program(book, cell))
    ctx = context(book, cell)
    listed, reasons = _bindings(model, ctx.processes), _reasons(model, ctx)
    offered = {a.p for a in model[s.Offered] if a.c == CELL}
    procs = sorted(book.processes, key=lambda p: p.id)
    playing = role_players(model, procs)

    def offer(p: ProcessDescription) -> Offer:
        players = playing[p.id]
        bindings = tuple(listed[p.id]) if all_bindings else (witness(players),)
        return Offer(p.id, p.label, bindings, binding_count(players), players)

    return Capabilities(
        cell.name,
        tuple(offer(p) for p in procs if p.id in offered),
        tuple(NotOffered(p.id, p.label, tuple(reasons[p.id])) for p in procs if p.id not in offered),
    )


def explain_process(cell: Cell, command: str, knowledge: Knowledge) -> ProcessExplanation:
    """Why ``command`` is (not) offered in ``cell``: its bindings, or every reason with provenance.

    Every binding is listed only for an offered command (on a big cell, why-not stays fast)."""
    caps = capabilities(cell, knowledge)
    if caps.offers(command):
        caps = capabilities(cell, knowledge, all_bindings=True)
    for o in caps.offered:
        if o.command == command:
            return ProcessExplanation(o.command, o.label, True, o.bindings, ())
    for n in caps.not_offered:
        if n.command == command:
            return ProcessExplanation(n.command, n.label, False, (), n.reasons)
    raise UnknownName("process command", command, knowledge.processes_by_id)
