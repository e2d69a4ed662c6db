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

``pnp_rounds_N`` counts the iterations of loop N (-1 once it has ended). An outcome takes
the branch of the most specific outcome it falls under; the conditions list the
outcomes the step's process declares. The chart's size does not depend on how often a
loop runs or which branches are taken.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from plugnproduce.codegen.specific import STEP
from plugnproduce.description.model import Branch, Loop, ProcessDescription, Task
from plugnproduce.description.outcomes import body_outcomes, falling_under, taken_by
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import local_name
from plugnproduce.statechart.model import Assign, Data, Transition

OUTCOME = "pnp_outcome"
"""The outcome the last step with outcomes in a loop reported."""


def rounds(n: int) -> str:
    """The datamodel variable counting the iterations of loop ``n`` (1-based)."""
    return f"pnp_rounds_{n}"


def _among(variable: str, names: tuple[str, ...]) -> str:
    """``variable`` is one of ``names`` (comparisons only: every SCXML interpreter's python datamodel reads them)."""
    return "(" + " or ".join(f"{variable} == {n!r}" for n in names) + ")" if names else "False"


def _none_of(variable: str, names: tuple[str, ...]) -> str:
    """``variable`` is none of ``names``."""
    return "(" + " and ".join(f"{variable} != {n!r}" for n in names) + ")" if names else "True"


def branch_variable(index: int) -> str:
    """The datamodel variable holding the outcome the step at position ``index`` reported (it has branches)."""
    return f"pnp_branch_{index}"


@dataclass(frozen=True)
class Outcomes:
    """The outcome names (as devices report them) each loop and branch reacts to."""

    until: dict[int, tuple[str, ...]] = field(default_factory=dict)
    goes_on: dict[int, tuple[str, ...]] = field(default_factory=dict)
    branches: dict[Branch, tuple[str, ...]] = field(default_factory=dict)


def outcome_names(task: Task, processes: dict[str, ProcessDescription], taxonomy: Taxonomy) -> Outcomes:
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
    for n, loop in enumerate(task.loops, start=1):
        out += _loop_transitions(n, loop, target, outcomes)
    for b in sorted(task.branches, key=lambda b: b.first):
        skip = f"{STEP} == {b.first - 1} and {_none_of(branch_variable(b.step), outcomes.branches[b])}"
        out.append(Transition(cond=skip, targets=[target], actions=[Assign(location=STEP, expr=str(b.last))]))
    return out


def _loop_transitions(n: int, loop: Loop, target: str, outcomes: Outcomes) -> list[Transition]:
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
        out.append(go(f"{STEP} == {first} and {count} == 0 and {stop}", (STEP, str(after)), (OUTCOME, "None"),
                      (count, "-1")))
        out.append(go(f"{STEP} == {after} and {count} >= 1 and {stop}", (OUTCOME, "None"), (count, "-1")))
    if loop.max == 1:
        out.append(go(f"{STEP} == {first} and {count} == 0", (STEP, str(after)), (count, "-1")))
    out.append(go(f"{STEP} == {first} and {count} == 0", (count, "1")))
    again = f"{STEP} == {after} and {count} >= 1"
    if loop.max is not None:
        again += f" and {count} + 1 < {loop.max}"
    out.append(go(again, (count, f"{count} + 1"), (STEP, str(first))))
    if loop.max is not None:
        out.append(go(f"{STEP} == {after} and {count} >= 1", (count, "-1")))
    return out
