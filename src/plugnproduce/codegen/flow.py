"""The task chart's control flow: loops as conditions on the datamodel, never unrolled.

The task chart runs step positions in order (``pnp_step`` counts them, see
:mod:`plugnproduce.codegen.task`). A loop's body is generated twice, as its first
iteration and as the iterations after it (they may start from other device states);
the state that picks the next step first applies the loop's rules, in this order:

1. a step of the body ended with the loop's ``until`` outcome (``pnp_outcome``): go on
   after the loop;
2. the first iteration ended: count it (and leave the loop if ``max`` is 1);
3. a later iteration ended: count it and run the later iterations' body again, unless
   ``max`` iterations have run.

``pnp_rounds_N`` counts the iterations of loop N (-1 once it has ended). The chart's size
does not depend on how often a loop runs.
"""

from __future__ import annotations

from plugnproduce.codegen.specific import STEP
from plugnproduce.description.model import Loop, Task
from plugnproduce.ontology.vocabulary import local_name
from plugnproduce.statechart.model import Assign, Data, Transition

OUTCOME = "pnp_outcome"
"""The outcome the last step with outcomes in a loop reported."""


def rounds(n: int) -> str:
    """The datamodel variable counting the iterations of loop ``n`` (1-based)."""
    return f"pnp_rounds_{n}"


def flow_data(task: Task) -> list[Data]:
    """The datamodel the loops need."""
    if not task.loops:
        return []
    return [Data(id=OUTCOME, expr="None"), *(Data(id=rounds(n), expr="0") for n in range(1, len(task.loops) + 1))]


def flow_transitions(task: Task, target: str) -> list[Transition]:
    """The loops' rules, as eventless transitions of the state that picks the next step (``target``)."""
    out: list[Transition] = []
    for n, loop in enumerate(task.loops, start=1):
        out += _loop_transitions(n, loop, target)
    return out


def _loop_transitions(n: int, loop: Loop, target: str) -> list[Transition]:
    count = rounds(n)
    # positions are 0-based in the chart: the step just ended is pnp_step - 1
    entry, first, after = loop.entry - 1, loop.first - 1, loop.last

    def go(cond: str, *assigns: tuple[str, str]) -> Transition:
        return Transition(cond=cond, targets=[target], actions=[Assign(location=loc, expr=e) for loc, e in assigns])

    out: list[Transition] = []
    if loop.until is not None:
        out.append(go(f"{OUTCOME} == {local_name(loop.until)!r} and {entry + 1} <= {STEP} <= {after}",
                      (STEP, str(after)), (OUTCOME, "None"), (count, "-1")))
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
