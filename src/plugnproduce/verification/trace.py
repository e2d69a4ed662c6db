"""A counterexample told move by move, each move at the description line it comes from.

The search keeps only the moves; they are played again here on fresh sessions with an
observer on the session that acts, so each move names the transitions it took: a device's
at its line in the device's chart, the controller's at its step in the task file.
"""

from __future__ import annotations

from plugnproduce.description.model import Step
from plugnproduce.statechart.model import Transition
from plugnproduce.statechart.runtime.events import TRANSITION_TAKEN, MetaEvent
from plugnproduce.verification.results import TraceStep
from plugnproduce.verification.world import CONTROLLER, ClosedWorld, Move, Violation, World, states_of


def explain(world: ClosedWorld, moves: list[Move], violation: Violation) -> list[TraceStep]:
    """The steps of a counterexample: ``moves`` from the start of ``world``, then ``violation``."""
    current, _ = world.start()
    first = [f"{m.name} to {d.id}" for d, q in zip(world.devices, current.requests, strict=True) for m in q]
    out = [TraceStep("controller starts the task" + (f"; sends {', '.join(first)}" if first else ""),
                     _task_where(world, current))]
    for move in moves:
        session = world.controller if move.session == CONTROLLER else world.sessions[world.devices_index(move.session)]
        taken: list[Transition] = []

        def seen(meta: MetaEvent, taken: list[Transition] = taken) -> None:
            if meta.name == TRANSITION_TAKEN:
                taken.append(meta.data["transition"])

        session.attach(seen)
        try:
            after, _ = world.apply(current, move)
        finally:
            session.detach(seen)
        out.append(_step(world, current, after, move, taken))
        current = after
    if violation.kind == "deadlock":
        out.append(TraceStep(violation.message, _task_where(world, current)))
    return out


def _step(world: ClosedWorld, before: World, after: World, move: Move, taken: list[Transition]) -> TraceStep:
    if move.session == CONTROLLER:
        sent = _sent(world, before, after)
        what = f"receives {move.name}" + (f" reporting {move.outcome}" if move.outcome else "")
        text = f"controller {what}" + (f"; sends {', '.join(sent)}" if sent else "")
        return TraceStep(text, _task_where(world, before))
    i = world.devices_index(move.session)
    device = world.devices[i]
    arrives = {"request": f"receives {move.name}", "timer": f"delay of {move.name} passes",
               "own": f"takes {move.name}"}[move.kind]
    states_before = states_of(before.devices[i])
    if taken:
        line = taken[0].line
        text = f"{device.id} {arrives}: {states_before} -> {states_of(after.devices[i])}"
    else:
        state = states_before.split("/")[-1]
        line = device.state(state).line if any(s.id == state for s in device.states) else None
        text = f"{device.id} {arrives} in state {states_before}, which has no transition for it"
    return TraceStep(text, f"{device.chart_file}:{line}" if line else device.chart_file)


def _sent(world: ClosedWorld, before: World, after: World) -> list[str]:
    """The requests the controller sent in a move: what its channels gained."""
    out = []
    for d, b, a in zip(world.devices, before.requests, after.requests, strict=True):
        out += [f"{m.name} to {d.id}" for m in a[len(b):]]
    return out


def _task_where(world: ClosedWorld, at: World) -> str:
    """The task file line of the step the controller is in."""
    step = _current_step(world, at)
    task = world.generated.task
    return str(task.where(step)) if step is not None else task.file


def _current_step(world: ClosedWorld, at: World) -> Step | None:
    ended = world.steps_ended(at)
    steps = world.generated.task.steps
    return steps[min(ended, len(steps) - 1)] if steps else None
