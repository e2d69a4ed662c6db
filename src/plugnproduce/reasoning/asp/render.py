"""Reason atoms → sentences an operator understands, naming the ontology terms and file:line they rest on."""

from __future__ import annotations

import difflib
from collections.abc import Mapping

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import DeviceDescription, ProcessDescription, Task, Where
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp.facts import SCALE
from plugnproduce.reasoning.asp.results import Problem, Reason


@dataclass(frozen=True)
class Context:
    """Everything a sentence may name: labels from the taxonomy, and where each thing is described."""

    taxonomy: Taxonomy
    processes: Mapping[str, ProcessDescription]
    devices: dict[str, DeviceDescription]
    cell: str
    task: Task | None = None

    def term(self, iri: str) -> str:
        """A term as ``label (pnp:Local)``."""
        curie = "pnp:" + iri[len(PNP_IRI):] if iri.startswith(PNP_IRI) else iri
        return f"{self.taxonomy.label(iri)} ({curie})"

    def state_where(self, d: str, x: str) -> Where:
        """Where a device's chart state is written."""
        dev = self.devices.get(d)
        if dev is None:
            return Where(self.cell)
        line = next((st.line for st in dev.states if st.id == x), None)
        return Where(dev.chart_file, line)

    def state_concept(self, d: str, x: str) -> str | None:
        """The concept a device's chart state is annotated with."""
        dev = self.devices.get(d)
        return next((st.concept for st in dev.states if st.id == x), None) if dev else None

    def role_where(self, p: str, r: str) -> Where:
        """Where a process's role is described."""
        return self.processes[p].role(r).where

    def region_where(self, p: str, r: str, i: int) -> Where:
        """Where the ``i``-th state (1-based) of a role's region is written."""
        proc = self.processes[p]
        return Where(proc.chart_file, proc.role(r).region[i - 1].line)

    def step_where(self, i: int, parameter: str | None = None) -> Where:
        """Where a step (or one of its parameter values) is written in the task file."""
        if self.task is None or not 1 <= i <= len(self.task.steps):
            return Where(self.task.file if self.task else "task")
        return self.task.where(self.task.steps[i - 1], parameter)

    def step_command(self, i: int) -> str:
        """The command of step ``i``."""
        return self.task.steps[i - 1].command if self.task and 1 <= i <= len(self.task.steps) else "?"


# ------------------------------------------------------------------ why a process is not offered


def no_skill(ctx: Context, a: s.NoSkill) -> Reason:
    """No device of the cell has the skill a role requires."""
    proc = ctx.processes[a.p]
    text = (f"role '{a.r}' of {a.p} needs a device that {ctx.term(a.s)}; "
            f"no device in cell '{ctx.cell}' has that skill")
    return Reason("no_skill", text, (a.s, proc.role(a.r).iri), (ctx.role_where(a.p, a.r),))


def lacks_state(ctx: Context, a: s.LacksState) -> Reason:
    """A device with the skill has no state of a concept the role's region visits."""
    proc, dev = ctx.processes[a.p], ctx.devices[a.d]
    text = (f"device '{a.d}' has the skill role '{a.r}' of {a.p} requires "
            f"({ctx.term(proc.role(a.r).required_skill)}), but its state chart has no state of concept "
            f"{ctx.term(a.con)}, which the role's region visits")
    where = (ctx.region_where(a.p, a.r, a.i), Where(dev.chart_file), dev.where)
    return Reason("lacks_state", text, (a.con, proc.role(a.r).required_skill, dev.iri), where)


def unreachable(ctx: Context, a: s.Unreachable) -> Reason:
    """A device has the states but cannot reach them in the order the region visits them."""
    proc, dev = ctx.processes[a.p], ctx.devices[a.d]
    prev = proc.role(a.r).region[a.i - 1].concept
    text = (f"device '{a.d}' cannot play role '{a.r}' of {a.p}: in its state chart no state of "
            f"concept {ctx.term(a.con)} is reachable from state '{a.x}' ({ctx.term(prev)}), "
            f"but the role's region goes there next")
    where = (ctx.region_where(a.p, a.r, a.i + 1), ctx.state_where(a.d, a.x), dev.where)
    return Reason("unreachable", text, (a.con, prev, dev.iri), where)


def no_argument(ctx: Context, a: s.NoArgument) -> Reason:
    """A device could play a role, but a request on its way needs an argument the process does not supply."""
    return missing_argument(ctx, a.p, a.r, a.d, a.req, a.q)


def missing_argument(ctx: Context, p: str, r: str, d: str, request: str, quantity: str) -> Reason:
    """Device ``d``'s request needs an argument (``quantity``) no parameter of process ``p`` hands it."""
    dev = ctx.devices[d]
    contract = dev.argument(request, quantity)
    text = (f"device '{d}' cannot play role '{r}' of {p}: its request {request} needs the argument "
            f"{ctx.term(quantity)}, and no parameter of {p} for role '{r}' supplies it (the device "
            f"declares no default)")
    line = next((t.line for t in dev.transitions if t.request and t.request.name == request
                 and quantity in t.accepts), None)
    where = (contract.where or dev.where, Where(dev.chart_file, line), ctx.role_where(p, r))
    return Reason("no_argument", text, (quantity, dev.iri), where)


# ------------------------------------------------------------------ why a step is not plausible


def since(ctx: Context, j: int | None, d: str) -> str:
    """Where a device's state came from: a step, the device's own report (a live cell), or power-up."""
    if j is None:
        return ""
    if j == 0:
        device = ctx.devices.get(d)
        return " (the state it reports)" if device is not None and device.reported_state else " (its initial state)"
    return f", left there by step {j} ({ctx.step_command(j)})"


def wrong_state(ctx: Context, a: s.WrongState, left_by: int | None) -> Problem:
    """A device is not in a state the step's role may start from."""
    concept = ctx.state_concept(a.d, a.x)
    now = f"{ctx.term(concept)}" if concept else "no concept"
    text = (f"step {a.i} ({ctx.step_command(a.i)}): device '{a.d}' (role '{a.r}') is in state "
            f"'{a.x}' [{now}]{since(ctx, left_by, a.d)}; the step needs it {ctx.term(a.need)}")
    p = ctx.step_command(a.i)
    rests = (ctx.state_where(a.d, a.x), ctx.region_where(p, a.r, 1)) if p in ctx.processes else ()
    reason = Reason("wrong_state", text, tuple(x for x in (concept, a.need) if x), rests)
    return Problem(a.i, p, "wrong_state", reason, ctx.step_where(a.i), a.r, a.d, a.x, concept, a.need)


def stuck(ctx: Context, a: s.Stuck) -> Problem:
    """From its state the device's chart has no path through the role's region."""
    p = ctx.step_command(a.i)
    text = (f"step {a.i} ({p}): device '{a.d}' (role '{a.r}') starts in state '{a.x}', but its state "
            f"chart has no path from there through the states the role's region visits")
    reason = Reason("stuck", text, (), (ctx.state_where(a.d, a.x), ctx.role_where(p, a.r)))
    return Problem(a.i, p, "stuck", reason, ctx.step_where(a.i), a.r, a.d, a.x, ctx.state_concept(a.d, a.x))


def binding_problem(ctx: Context, kind: str, i: int, r: str, devices: list[str],
                    missing: tuple[s.MissingArg, ...] = ()) -> Problem:
    """A role of a step that cannot be bound: none fits, several fit, or the named device cannot play it.

    ``missing`` are the arguments devices that would otherwise play the role lack: named in the text.
    """
    p = ctx.step_command(i)
    proc = ctx.processes.get(p)
    role = next((x for x in proc.roles if x.name == r), None) if proc else None
    needs = f", which needs a device that {ctx.term(role.required_skill)}" if role else ""
    head = f"step {i} ({p}): role '{r}'"
    named = devices[0] if devices else "?"
    if kind == "no_device":
        text = f"step {i} ({p}): no device in cell '{ctx.cell}' can play role '{r}'{needs}"
    elif kind == "ambiguous":
        text = f"{head} is not bound and several devices fit: {', '.join(sorted(devices))}; bind one in the task"
    elif kind == "absent":
        text = f"{head} is bound to device '{named}', which is not in cell '{ctx.cell}'"
    elif kind == "cannot_play":
        text = f"{head}{needs}, is bound to device '{named}', which cannot play it"
    else:
        roles = ", ".join(x.name for x in proc.roles) if proc else "-"
        text = f"{head} is bound, but {p} has no such role (its roles: {roles})"
    rests: tuple[Where, ...] = (role.where,) if role else ()
    iris: tuple[str, ...] = (role.required_skill,) if role else ()
    lacks = [m for m in missing if m.p == p and m.r == r and (kind == "no_device" or m.d == named)]
    if kind in ("no_device", "cannot_play") and lacks:
        why = [missing_argument(ctx, m.p, m.r, m.d, m.req, m.q) for m in lacks]
        text += "; " + "; ".join(w.text for w in why)
        rests += tuple(x for w in why for x in w.where)
        iris += tuple(x for w in why for x in w.iris)
    reason = Reason(kind, text, iris, rests)
    device = devices[0] if len(devices) == 1 else None
    return Problem(i, p, kind, reason, ctx.step_where(i), r, device)


def unknown_command(ctx: Context, a: s.UnknownCommand) -> Problem:
    """A step names no known process command."""
    known = ", ".join(sorted(ctx.processes))
    close = difflib.get_close_matches(a.p, sorted(ctx.processes), n=2)
    hint = f"; did you mean {' or '.join(close)}?" if close else f"; known: {known}"
    reason = Reason("unknown_command", f"step {a.i}: unknown process command '{a.p}'{hint}")
    return Problem(a.i, a.p, "unknown_command", reason, ctx.step_where(a.i))


def _num(v: int) -> str:
    return format(v / SCALE, "g")


def exact(value: float) -> str:
    """A number to 15 significant digits, all a float holds for certain (``1.7e+308``, ``120``,
    ``150.123456789``): never rounded to 6 digits, never clamped."""
    return format(value, ".15g")


def _given(ctx: Context, i: int, n: str, v: int) -> str:
    """The value step ``i`` gives ``n``, exactly as the task holds it (ASP's thousandths are clamped)."""
    if ctx.task is not None and 1 <= i <= len(ctx.task.steps):
        value = ctx.task.steps[i - 1].params.get(n)
        if isinstance(value, int | float) and not isinstance(value, bool):
            return exact(value)
    return _num(v)


def parameter_problem(ctx: Context, a: s.BadType | s.TooLow | s.TooHigh | s.UnknownParam) -> Problem:
    """A parameter value that does not fit its process's declaration."""
    p = ctx.step_command(a.i)
    proc = ctx.processes.get(p)
    par = next((x for x in proc.parameters if x.name == a.n), None) if proc else None
    unit = f" {par.unit}" if par and par.unit else ""
    head = f"step {a.i} ({p}): parameter {a.n}"
    given = _given(ctx, a.i, a.n, a.v) if isinstance(a, s.TooLow | s.TooHigh) else ""
    if isinstance(a, s.BadType):
        kind, text = "bad_type", f"{head} is not a {a.ty} value"
    elif isinstance(a, s.TooLow):
        kind, text = "too_low", f"{head} = {given}{unit} is below its minimum {_num(a.bound)}{unit}"
    elif isinstance(a, s.TooHigh):
        kind, text = "too_high", f"{head} = {given}{unit} is above its maximum {_num(a.bound)}{unit}"
    else:
        names = ", ".join(x.name for x in proc.parameters) if proc else "-"
        kind, text = "unknown_param", f"{head} is not declared by {p} (its parameters: {names})"
    iris = (par.quantity,) if par else ()
    reason = Reason(kind, text, iris, (par.where,) if par else ())
    return Problem(a.i, p, kind, reason, ctx.step_where(a.i, a.n), parameter=a.n)


def device_state(ctx: Context, i: int, r: str, d: str, x: str, left_by: int | None) -> Reason:
    """One sentence on a device a step uses: its state, where it came from, what the role needs."""
    p = ctx.step_command(i)
    concept = ctx.state_concept(d, x)
    now = ctx.term(concept) if concept else "no concept"
    need = ctx.processes[p].role(r).start_concept if p in ctx.processes else None
    ok = need is not None and concept is not None and ctx.taxonomy.is_a(concept, need)
    needs = f"; role '{r}' needs it {ctx.term(need)}: {'satisfied' if ok else 'not satisfied'}" if need else ""
    text = f"device '{d}' is in state '{x}' [{now}]{since(ctx, left_by, d)}{needs}"
    rests = (ctx.state_where(d, x),) + ((ctx.region_where(p, r, 1),) if need else ())
    return Reason("device_state", text, tuple(c for c in (concept, need) if c), rests)
