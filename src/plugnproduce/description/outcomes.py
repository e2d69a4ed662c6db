"""Which outcomes a task's branches and loops react to, and what is wrong with them (no cell needed).

An outcome a step's process reports takes the step's branch of the most specific outcome
it falls under (``BinEmpty ⊑ NoPartFound``); a loop ends ``until`` an outcome that falls
under its own, and goes on ``while`` one does. The same findings serve ``pnp validate``
(at the file's line) and ``pnp check`` (at the step).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping

from plugnproduce.deferred import dataclass
from plugnproduce.description.flow import Branch, Loop
from plugnproduce.description.model import ProcessDescription, Task
from plugnproduce.ontology.iris import concept_iri, local_name
from plugnproduce.ontology.names import did_you_mean
from plugnproduce.ontology.taxonomy import Taxonomy


@dataclass(frozen=True)
class FlowFinding:
    """Something wrong with a branch or a loop: its line in the task file and the step it concerns."""

    line: int | None
    step: int
    command: str
    text: str


def branch_of(outcome: str, branches: tuple[Branch, ...], taxonomy: Taxonomy) -> Branch | None:
    """The branch an outcome takes: the one of the most specific outcome it falls under, else None."""
    fits = [b for b in branches if taxonomy.is_a(outcome, b.outcome)]
    return next((b for b in fits if not any(o is not b and taxonomy.is_a(o.outcome, b.outcome)
                                            and o.outcome != b.outcome for o in fits)), None)


def falling_under(outcome: str, outcomes: tuple[str, ...], taxonomy: Taxonomy) -> tuple[str, ...]:
    """The outcomes of ``outcomes`` that are ``outcome`` or a more specific one."""
    return tuple(o for o in outcomes if taxonomy.is_a(o, outcome))


def taken_by(branch: Branch, siblings: tuple[Branch, ...], outcomes: tuple[str, ...],
             taxonomy: Taxonomy) -> tuple[str, ...]:
    """The outcomes of a step's process that take ``branch`` (of the step's branches ``siblings``)."""
    return tuple(o for o in outcomes if branch_of(o, siblings, taxonomy) == branch)


def _written(task: Task, index: int) -> bool:
    """Whether position ``index`` is as the file writes it (not a loop's later-iterations copy)."""
    return not any(lp.first <= index <= lp.last for lp in task.loops)


def flow_findings(task: Task, processes: Mapping[str, ProcessDescription], taxonomy: Taxonomy) -> Iterator[FlowFinding]:
    """Unknown outcomes, branches that can never run, loops that never end (or never go on) on theirs."""
    for b in task.branches:
        if _written(task, b.step):
            yield from _branch_findings(task, b, processes, taxonomy)
    for loop in task.loops:
        if _written(task, loop.entry):  # a loop inside another's later iterations: its copy, found already
            yield from _loop_findings(task, loop, processes, taxonomy)


def _unknown(iri: str, taxonomy: Taxonomy) -> str | None:
    if taxonomy.is_kind(iri, "Outcome") or iri == concept_iri("Outcome"):
        return None
    return (f"{local_name(iri)} is not an outcome of the ontology"
            + did_you_mean(iri, taxonomy.classes_of_kind("Outcome")))


def _branch_findings(task: Task, b: Branch, processes: Mapping[str, ProcessDescription],
                     taxonomy: Taxonomy) -> Iterator[FlowFinding]:
    step = task.steps[b.step - 1]
    head = f"step {b.step} ({step.command}): branch {local_name(b.outcome)}"
    unknown = _unknown(b.outcome, taxonomy)
    if unknown:
        yield FlowFinding(b.line, b.step, step.command, f"{head}: {unknown}")
        return
    process = processes.get(step.command)
    if process is None:
        return  # an unknown command is a finding of its own
    siblings = task.branches_of(b.step)
    goes_on = tuple(o for o in process.outcomes if ending_loop(task, b.step, o, taxonomy) is None)
    if taken_by(b, siblings, goes_on, taxonomy):
        return
    taking = taken_by(b, siblings, process.outcomes, taxonomy)
    until = next((u for o in taking if (u := ending_loop(task, b.step, o, taxonomy)) is not None), None)
    if taking and until is not None:
        names = ", ".join(local_name(o) for o in taking)
        yield FlowFinding(b.line, b.step, step.command, f"{head} is unreachable: the outcome that would take it "
                          f"({names}) ends the loop first (until {local_name(until)})")
        return
    ends = ", ".join(local_name(o) for o in process.outcomes)
    why = (f"{process.id} ends with {ends} only" if ends else f"{process.id} reports no outcome")
    if ends and falling_under(b.outcome, process.outcomes, taxonomy):
        why += ", and each of those that falls under it has a branch of its own"
    yield FlowFinding(b.line, b.step, step.command, f"{head} is unreachable: {why}")


def loop_ending(task: Task, index: int, outcome: str, taxonomy: Taxonomy) -> Loop | None:
    """The innermost loop around step position ``index`` whose ``until`` ``outcome`` falls under, if any:
    the loop that outcome ends."""
    return next((lp for lp in reversed(task.loops_at(index))
                 if lp.until is not None and taxonomy.is_a(outcome, lp.until)), None)


def ending_loop(task: Task, index: int, outcome: str, taxonomy: Taxonomy) -> str | None:
    """The ``until`` of the loop ``outcome`` ends at step position ``index`` (:func:`loop_ending`), if any."""
    loop = loop_ending(task, index, outcome, taxonomy)
    return loop.until if loop is not None else None


def body_outcomes(task: Task, loop: Loop, processes: Mapping[str, ProcessDescription]) -> tuple[str, ...]:
    """The outcomes the steps of a loop's body can end with."""
    body = task.steps[loop.entry - 1: loop.first - 1]
    return tuple(dict.fromkeys(o for s in body if s.command in processes for o in processes[s.command].outcomes))


def _ends_on(task: Task, loop: Loop, until: str, processes: Mapping[str, ProcessDescription],
             taxonomy: Taxonomy) -> bool:
    """Whether a step of the loop's body can end with an outcome under ``until`` that no inner loop ends first."""
    return any(taxonomy.is_a(o, until) and loop_ending(task, s.index, o, taxonomy) == loop
               for s in task.steps[loop.entry - 1: loop.first - 1] if s.command in processes
               for o in processes[s.command].outcomes)


def _loop_findings(task: Task, loop: Loop, processes: Mapping[str, ProcessDescription],
                   taxonomy: Taxonomy) -> Iterator[FlowFinding]:
    first = task.steps[loop.entry - 1]
    outcomes = body_outcomes(task, loop, processes)
    known = ", ".join(sorted({local_name(o) for o in outcomes})) or "none"
    for word, iri in (("until", loop.until), ("while", loop.while_outcome)):
        if iri is None:
            continue
        unknown = _unknown(iri, taxonomy)
        if unknown:
            yield FlowFinding(loop.line, loop.entry, first.command, f"loop {word} {local_name(iri)}: {unknown}")
        elif not falling_under(iri, outcomes, taxonomy):
            effect = "the loop never ends on it" if word == "until" else "the loop never goes on after iteration 1"
            yield FlowFinding(loop.line, loop.entry, first.command,
                              f"loop {word} {local_name(iri)}: no step of its body can end with that outcome, "
                              f"so {effect}; its steps' outcomes: {known}")
        elif word == "until" and not _ends_on(task, loop, iri, processes, taxonomy):
            yield FlowFinding(loop.line, loop.entry, first.command,
                              f"loop until {local_name(iri)}: every step of its body that can end with that outcome "
                              "lies in an inner loop that ends on it first, so the loop never ends on it")
        elif word == "while" and loop.max is None and loop.until is None and \
                set(falling_under(iri, outcomes, taxonomy)) == set(outcomes):
            yield FlowFinding(loop.line, loop.entry, first.command,
                              f"loop while {local_name(iri)} has no exit: every outcome its steps can end with "
                              f"({known}) lets it go on, and it has no max")
