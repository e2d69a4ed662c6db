"""Structural checks of a read chart: ids unique, references resolved, initial states present.

These are what the W3C schema cannot say (or says without a line the user can act on):
each problem is a :class:`~plugnproduce.errors.DescriptionError` naming what was found
and what was expected.
"""

from __future__ import annotations

from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.statechart.model import Chart, History, Parallel, State, StateNode, Transition


def check_structure(chart: Chart, source: str) -> None:
    """Raise a :class:`DescriptionError` for the first structural error of ``chart``.

    Inline child charts (``<invoke><content><scxml>``) are documents of their own, checked
    when they are invoked.
    """
    if not any(not isinstance(c, History) for c in chart.children):
        raise DescriptionError("the chart has no state; expected at least one <state>, <parallel> or <final>",
                               source, chart.line)
    ids = _ids(chart, source)
    _check_initial(chart, chart.initial, ids, source, chart.line, "the chart's initial")
    for node in chart.states():
        if isinstance(node, State):
            _check_state(node, ids, source)
        elif isinstance(node, History):
            _check_history(node, ids, source)
        if isinstance(node, State | Parallel):
            for t in node.transitions:
                _check_targets(t, ids, source)


def _ids(chart: Chart, source: str) -> dict[str, StateNode]:
    ids: dict[str, StateNode] = {}
    for node in chart.states():
        if node.id is None:
            continue
        if node.id in ids:
            raise DescriptionError(f"state id {node.id!r} is used twice (first on line {ids[node.id].line}); "
                                   "expected unique ids", source, node.line)
        ids[node.id] = node
    return ids


def _check_initial(container: Chart | State, initial: list[str], ids: dict[str, StateNode], source: str,
                   line: int | None, what: str) -> None:
    for target in initial:
        node = ids.get(target)
        if node is None:
            raise DescriptionError(f"{what} names the state {excerpt(target)!r}, which does not exist; "
                                   "expected the id of a state in the chart", source, line)
        if not _is_descendant(node, container):
            raise DescriptionError(f"{what} names the state {excerpt(target)!r}, which is not inside "
                                   f"{_label(container)}; expected a descendant", source, line)


def _check_state(state: State, ids: dict[str, StateNode], source: str) -> None:
    if state.initial and state.is_atomic:
        raise DescriptionError(f"the atomic state {state.id!r} has an initial attribute; "
                               "expected one only on a state with child states", source, state.line)
    if state.initial_element is not None:
        t = state.initial_element.transition
        if not t.targets:
            raise DescriptionError(f"the <initial> of state {state.id!r} has a transition without target; "
                                   "expected a target", source, t.line)
        _check_initial(state, t.targets, ids, source, t.line, f"the <initial> of state {state.id!r}")
    else:
        _check_initial(state, state.initial, ids, source, state.line, f"the initial of state {state.id!r}")


def _check_history(history: History, ids: dict[str, StateNode], source: str) -> None:
    if history.transition is not None:
        _check_targets(history.transition, ids, source)


def _check_targets(t: Transition, ids: dict[str, StateNode], source: str) -> None:
    for target in t.targets:
        if target not in ids:
            raise DescriptionError(f"transition target {target!r} does not exist; expected the id of a state "
                                   "in the chart", source, t.line)


def _is_descendant(node: StateNode, container: Chart | State) -> bool:
    if isinstance(container, Chart):
        return True
    stack: list[StateNode] = list(container.children)
    while stack:
        child = stack.pop()
        if child is node:
            return True
        if isinstance(child, State | Parallel):
            stack.extend(child.children)
    return False


def _label(container: Chart | State) -> str:
    return "the chart" if isinstance(container, Chart) else f"state {container.id!r}"
