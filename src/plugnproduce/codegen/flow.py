"""The task chart's control flow: loops and branches as conditions on the datamodel, never unrolled.

The task chart runs step positions in order (``pnp_step`` counts the steps done, see
:mod:`plugnproduce.codegen.task`). A loop's body is generated twice, as its first
iteration and as the iterations after it (they may start from other device states);
a branch's steps follow the step whose outcome decides. The state that picks the next
step first applies these rules, in this order:

1. a step of a loop's body ended with an outcome that falls under the loop's ``until``
   (``pnp_outcome``): go on after the loop;
2. an iteration ended and the last outcome its body reported does not fall under the
   loop's ``while``: go on after the loop;
3. the first iteration ended: count it (and leave the loop if ``max`` is 1);
4. a later iteration ended: count it and run the later iterations' body again, unless
   ``max`` iterations have run;
5. a branch's first step is next, but the outcome its step reported
   (``pnp_branch_N``, N the step's position) does not take the branch: skip its steps.

Loops nest: a loop inside another's body is a loop record in each copy of that body, each
with its own ``pnp_rounds_N`` (N its place in :attr:`Task.loops`). The rules of an inner
loop come before those of the loops around it, so an outcome ends the innermost loop whose
``until`` it falls under; and when a loop runs its later iterations' body again it sets the
counters of the loops inside that body back to 0, so that they loop again.

``pnp_rounds_N`` counts the iterations of loop N (-1 once it has ended). An outcome takes
the branch of the most specific outcome it falls under; the conditions list the
outcomes the step's process declares. The chart's size does not depend on how often a
loop runs or which branches are taken.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from plugnproduce.chartnames import OUTCOME, STEP, branch_variable, rounds
from plugnproduce.description.model import Branch, Loop, ProcessDescription, Task
from plugnproduce.description.outcomes import body_outcomes, falling_under, taken_by
from plugnproduce.ontology.iris import local_name
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.statechart.model import Assign, Data, Transition


def _among(variable: str, names: tuple[str, ...]) -> str:
    """``variable`` is one of ``names`` (comparisons only: every SCXML interpreter's python datamodel reads them)."""
    return "(" + " or ".join(f"{variable} == {n!r}" for n in names) + ")" if names else "False"


def _none_of(variable: str, names: tuple[str, ...]) -> str:
    """``variable`` is none of ``names``."""
    return "(" + " and ".join(f"{variable} != {n!r}" for n in names) + ")" if names else "True"


@dataclass(frozen=True)
class Outcomes:
    """The outcome names (as devices report them) each loop and branch reacts to."""

    until: dict[int, tuple[str, ...]] = field(default_factory=dict)
    goes_on: dict[int, tuple[str, ...]] = field(default_factory=dict)
    branches: dict[Branch, tuple[str, ...]] = field(default_factory=dict)


def outcome_names(task: Task, processes: Mapping[str, ProcessDescription], taxonomy: Taxonomy) -> Outcomes:
    """Per loop (1-based) the outcomes that end it or let it go on, per branch the outcomes that take it."""
    out = Outcomes()
    for n, loop in enumerate(task.loops, start=1):
        body = body_outcomes(task, loop, processes)
        for iri, names in ((loop.until, out.until), (loop.while_outcome, out.goes_on)):
            if iri is not None:
                names[n] = tuple(sorted({local_name(o) for o in falling_under(iri, body, taxonomy)}
                                        | {local_name(iri)}))
    for b in task.branches:
        process = processes.get(task.steps[b.step - 1].command)
        declared = process.outcomes if process is not None else ()
        out.branches[b] = tuple(sorted(local_name(o) for o in taken_by(b, task.branches_of(b.step), declared,
                                                                           taxonomy)))
    return out


def flow_data(task: Task) -> list[Data]:
    """The datamodel the loops need."""
    if not task.loops:
        return []
    return [Data(id=OUTCOME, expr="None"), *(Data(id=rounds(n), expr="0") for n in range(1, len(task.loops) + 1))]


def flow_transitions(task: Task, target: str, outcomes: Outcomes) -> list[Transition]:
    """The loops' and branches' rules, as eventless transitions of the state that picks the next step (``target``)."""
    out: list[Transition] = []
    numbered = list(enumerate(task.loops, start=1))
    for n, loop in sorted(numbered, key=lambda nl: (nl[1].last - nl[1].entry, nl[0])):  # inner loops first
        inside = tuple(m for m, lp in numbered if loop.first <= lp.entry <= loop.last)
        nested = any(lp.entry <= loop.entry and loop.last <= lp.last for lp in task.loops if lp != loop)
        out += _loop_transitions(n, loop, target, outcomes, _Nesting(inside, nested))
    for b in sorted(task.branches, key=lambda b: b.first):
        skip = f"{STEP} == {b.first - 1} and {_none_of(branch_variable(b.step), outcomes.branches[b])}"
        out.append(Transition(cond=skip, targets=[target], actions=[Assign(location=STEP, expr=str(b.last))]))
    return out


@dataclass(frozen=True)
class _Nesting:
    """Where a loop lies among the others."""

    inside: tuple[int, ...]
    """The loops (1-based) inside its later iterations' body: their counters restart with each iteration."""
    nested: bool
    """Whether it lies in another loop's body (its ``while`` keeps ``pnp_outcome`` for the outer loops)."""


def _loop_transitions(n: int, loop: Loop, target: str, outcomes: Outcomes, nesting: _Nesting) -> list[Transition]:
    """One loop's rules, as transitions back to ``target``."""
    count = rounds(n)
    # positions are 0-based in the chart: the step just ended is pnp_step - 1
    entry, first, after = loop.entry - 1, loop.first - 1, loop.last

    def go(cond: str, *assigns: tuple[str, str]) -> Transition:
        return Transition(cond=cond, targets=[target], actions=[Assign(location=loc, expr=e) for loc, e in assigns])

    out: list[Transition] = []
    if n in outcomes.until:
        out.append(go(f"{_among(OUTCOME, outcomes.until[n])} and {entry + 1} <= {STEP} <= {after}",
                      (STEP, str(after)), (OUTCOME, "None"), (count, "-1")))
    if n in outcomes.goes_on:
        stop = _none_of(OUTCOME, outcomes.goes_on[n])
        keep: tuple[tuple[str, str], ...] = () if nesting.nested else ((OUTCOME, "None"),)
        out.append(go(f"{STEP} == {first} and {count} == 0 and {stop}", (STEP, str(after)), *keep, (count, "-1")))
        out.append(go(f"{STEP} == {after} and {count} >= 1 and {stop}", *keep, (count, "-1")))
    if loop.max == 1:
        out.append(go(f"{STEP} == {first} and {count} == 0", (STEP, str(after)), (count, "-1")))
    out.append(go(f"{STEP} == {first} and {count} == 0", (count, "1")))
    again = f"{STEP} == {after} and {count} >= 1"
    if loop.max is not None:
        again += f" and {count} + 1 < {loop.max}"
    restart = tuple((rounds(m), "0") for m in nesting.inside)
    out.append(go(again, (count, f"{count} + 1"), (STEP, str(first)), *restart))
    if loop.max is not None:
        out.append(go(f"{STEP} == {after} and {count} >= 1", (count, "-1")))
    return out
