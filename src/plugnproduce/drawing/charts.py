"""The Graphviz graph of a chart model.

Compound and parallel states become clusters (a parallel's regions side by side), atomic states
become nodes labelled with their id and ontology concept, and every transition an edge labelled
``event [cond] / commands``. A chart run by a plan (task, closed-world, device program) is drawn
top to bottom in the order of its steps: a task's steps as one box each (process and binding),
folded into columns, with at most one step expanded into its regions; a device program's
segments as clusters side by side, each naming the steps that run it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from itertools import pairwise

import graphviz

from plugnproduce.drawing.steps import Plan, PlanStep, find_plan, pnp
from plugnproduce.ontology.iris import local_name
from plugnproduce.statechart.model import Chart, Final, Parallel, Raise, Send, State, StateNode, Transition, walk

COLUMN = 10
"""The fewest steps per column of a task's picture; further steps start a new column to the right."""
_ASPECT = 2.7
"""How many step boxes, stacked, are as tall as one is wide (spacing included)."""
SHOWN = 200
"""The most step boxes a picture draws: a longer task shows those around the expanded step (or its
first ones) and one box for the steps before and one for those after."""
START = "pnp_start"
_Edge = tuple[str, str, str, "str | None"]


def column_length(steps: int) -> int:
    """Steps per column for a task of ``steps`` steps: at least :data:`COLUMN`, and as many as keep
    the picture about as wide as it is tall."""
    return max(COLUMN, math.ceil(math.sqrt(_ASPECT * steps)))


def shown_steps(steps: int, expanded: int | None = None) -> tuple[int, int]:
    """The first and last step a picture draws as boxes: all, or :data:`SHOWN` around ``expanded``."""
    if steps <= SHOWN:
        return 1, steps
    first = max(1, min((expanded or 1) - SHOWN // 2, steps - SHOWN + 1))
    return first, first + SHOWN - 1


def step_node(number: int) -> str:
    """The Graphviz node (or, expanded, cluster suffix) of a task's step."""
    return f"pnp_step_{number}"


def _is_compound(node: StateNode) -> bool:
    return isinstance(node, Parallel) or (isinstance(node, State) and bool(node.children))


def _first(node: StateNode) -> StateNode:
    while isinstance(node, State | Parallel) and node.children:
        node = node.children[0]
    return node


def _last(node: StateNode) -> StateNode:
    """The last state of a step body's first region: where the step ends."""
    if isinstance(node, Parallel) and node.children:
        node = node.children[0]
    while isinstance(node, State | Parallel) and node.children:
        node = node.children[-1]
    return node


def _label(t: Transition) -> str:
    parts = []
    if t.event:
        parts.append(t.event)
    if t.cond:
        parts.append(f"[{t.cond}]")
    actions = []
    for a in (n for action in t.actions for n in walk(action, into_charts=False)):
        if isinstance(a, Send | Raise):
            verb = "send" if isinstance(a, Send) else "raise"
            target = f" → {a.target}" if isinstance(a, Send) and a.target else ""
            actions.append(f"{verb} {a.event or ''}{target}")
    if actions:
        parts.append("/ " + "\\n".join(actions))
    return "\\n".join(parts)


def _state_label(node: StateNode) -> str:
    concept = pnp(node, "concept")
    return f"{node.id}\\n«{local_name(concept)}»" if concept else str(node.id)


def _cluster_label(node: State | Parallel) -> str:
    """A compound state's name, its concept (which every state inside it shares) and its role."""
    concept, role = pnp(node, "concept"), pnp(node, "role")
    return f"{node.id}" + (f" «{local_name(concept)}»" if concept else "") + (f" (role {role})" if role else "")


def _initial_child(container: Chart | State) -> str | None:
    """The state ``container`` enters by default: its ``initial``, its ``<initial>``'s target or its first child."""
    if isinstance(container, State) and container.initial_element is not None:
        return next(iter(container.initial_element.transition.targets), None)
    if container.initial:
        return container.initial[0]
    return next((c.id for c in container.children if isinstance(c, State | Parallel | Final)), None)


def _step_label(step: PlanStep) -> str:
    lines = [step.title, *step.binding_text()]
    if step.chart:
        lines.append(step.chart)
    return "\\n".join(lines)


def _runs(numbers: Iterable[int], most: int = 6) -> str:
    """``1, 3–6``: step numbers as ranges; past ``most`` ranges, the first few and how many in all."""
    spans: list[list[int]] = []
    count = 0
    for n in numbers:
        count += 1
        if spans and spans[-1][1] == n - 1:
            spans[-1][1] = n
        else:
            spans.append([n, n])
    text = ", ".join(str(a) if a == b else f"{a}–{b}" for a, b in spans[:most])
    return text if len(spans) <= most else f"{text}, … ({count} in all)"


def _subtree(node: StateNode) -> set[str]:
    out = {node.id or ""}
    for child in node.children if isinstance(node, State | Parallel) else ():
        out |= _subtree(child)
    return out


class _Drawing:
    """One chart being drawn: the nodes and clusters go in as the chart is walked, the edges after."""

    def __init__(self, graph: graphviz.Digraph, chart: Chart, plan: Plan | None, expand: int | None) -> None:
        self.graph, self.chart, self.plan = graph, chart, plan
        self.ids = {node.id: node for node in chart.states() if node.id}
        self.edges: list[_Edge] = []
        self.hidden: set[str] = set()
        self.expanded: PlanStep | None = None
        self._segment_of = self._segment_states(plan) if plan and not plan.is_task else {}
        self._folded = False
        if plan and plan.is_task:
            self.hidden = {plan.picker.id or ""}.union(*(_subtree(b) for b in plan.bodies.values()))
            if expand is not None and 1 <= expand <= len(plan.steps):
                self.expanded = plan.steps[expand - 1]
                self.hidden -= _subtree(self.ids[self.expanded.body])

    def add(self, graph: graphviz.Digraph, container: Chart | State | Parallel) -> None:
        """Draw the states of ``container`` into ``graph``, and note their transitions."""
        plan = self.plan
        if plan and container is plan.container:
            if plan.is_task:
                self._task_steps(graph, plan)
            else:
                self._segments(graph, plan)
        drawn_apart = set(self._segment_of) | (set(plan.bodies) if plan and plan.is_task else set())
        for child in container.children:
            if isinstance(child, State | Parallel | Final) and child.id not in self.hidden:
                if not (plan and container is plan.container and child.id in drawn_apart):
                    self._state(graph, child)

    def _state(self, graph: graphviz.Digraph, child: State | Parallel | Final) -> None:
        sid = child.id or ""
        if isinstance(child, State | Parallel) and _is_compound(child):
            with graph.subgraph(name=f"cluster_{sid}") as sub:
                style = "dashed" if isinstance(child, Parallel) else "rounded"
                sub.attr(label=_cluster_label(child), style=style)
                self.add(sub, child)
                if isinstance(child, State):
                    self.initial(sub, child)
        else:
            final = "2" if isinstance(child, Final) else "1"
            graph.node(sid, _state_label(child), shape="box", style="rounded", peripheries=final)
        for t in child.transitions if isinstance(child, State | Parallel) else ():
            for target in t.targets:
                self.edges.append((sid, target, _label(t), f"cluster_{sid}" if _is_compound(child) else None))

    def initial(self, graph: graphviz.Digraph, container: Chart | State) -> None:
        """A dot with an arrow to the state ``container`` starts in, when that is an atomic state (a compound one
        shows its own); a chart run by a plan shows its steps instead."""
        first = _initial_child(container)
        if self.plan is None and first in self.ids and not _is_compound(self.ids[first]):
            dot = f"{container.id if isinstance(container, State) else 'pnp'}__initial"
            graph.node(dot, "", shape="point", width="0.1")
            self.edges.append((dot, first, "", None))

    # ------------------------------------------------------------ a task's steps

    def _task_steps(self, graph: graphviz.Digraph, plan: Plan) -> None:
        graph.node(START, "", shape="point", width="0.12")
        names = [START]
        first, last = shown_steps(len(plan.steps), self.expanded.number if self.expanded else None)
        if first > 1:
            names.append("pnp_steps_before")
            graph.node(names[-1], f"steps 1–{first - 1}\\n(not drawn)", shape="box", style="dashed,rounded")
        for step in plan.steps[first - 1:last]:
            names.append(step_node(step.number))
            if step is self.expanded:
                with graph.subgraph(name=f"cluster_{names[-1]}") as sub:
                    sub.attr(label=_step_label(step).replace("\\n", " · ", 1), style="bold,rounded")
                    self.add(sub, self.ids[step.body])  # type: ignore[arg-type]
            else:
                graph.node(names[-1], _step_label(step), shape="box", style="rounded,filled", fillcolor="#f4f4f4")
        if last < len(plan.steps):
            names.append("pnp_steps_after")
            graph.node(names[-1], f"steps {last + 1}–{len(plan.steps)}\\n(not drawn)", shape="box",
                       style="dashed,rounded")
        column = column_length(len(names) - 1)
        ends = [self._entry(n) for n in names]
        exits = [self._exit(n) for n in names]
        for i in range(1, len(names)):
            attrs: dict[str, str] = {}
            if i % column == 1 and i > 1:
                attrs.update(constraint="false", style="dashed", color="#808080")
            if self._is_expanded(names[i - 1]):
                attrs["ltail"] = f"cluster_{names[i - 1]}"
            if self._is_expanded(names[i]):
                attrs["lhead"] = f"cluster_{names[i]}"
            graph.edge(exits[i - 1], ends[i], **attrs)
        if plan.end and plan.end in self.ids:
            self.edges.append(("", plan.end, "", exits[-1]))
        tops = [ends[i] for i in range(1, len(names), column)]
        if len(tops) > 1:
            with graph.subgraph() as row:
                row.attr(rank="same")
                for a, b in pairwise(tops):
                    row.edge(a, b, style="invis")

    def _is_expanded(self, name: str) -> bool:
        return self.expanded is not None and name == step_node(self.expanded.number)

    def _entry(self, name: str) -> str:
        if self._is_expanded(name) and self.expanded:
            return _first(self.ids[self.expanded.body]).id or ""
        return name

    def _exit(self, name: str) -> str:
        if self._is_expanded(name) and self.expanded:
            return _last(self.ids[self.expanded.body]).id or ""
        return name

    # ------------------------------------------------------------ a device program's segments

    def _segment_states(self, plan: Plan) -> dict[str, str]:
        """Each state of a device program's segments → the segment's first state."""
        out: dict[str, str] = {}
        stop = {plan.picker.id, plan.end}
        for body in plan.bodies:
            todo = [body]
            while todo:
                sid = todo.pop()
                node = self.ids.get(sid)
                if node is None or sid in out or sid in stop:
                    continue
                out[sid] = body
                todo.extend(t for tr in getattr(node, "transitions", ()) for t in tr.targets)
        return out

    def _segments(self, graph: graphviz.Digraph, plan: Plan) -> None:
        bodies = list(plan.bodies)
        row = math.ceil(math.sqrt(len(bodies))) if len(bodies) > COLUMN else len(bodies)  # about square
        members: dict[str, list[str]] = {body: [] for body in bodies}
        for sid, first in self._segment_of.items():
            members[first].append(sid)
        runs_of: dict[str, list[int]] = {body: [] for body in bodies}
        for step in plan.steps:
            runs_of[step.body].append(step.number)
        for k, body in enumerate(bodies, start=1):
            runs = _runs(runs_of[body])
            with graph.subgraph(name=f"cluster_segment_{body}") as sub:
                sub.attr(label=f"segment {k} · device's runs {runs}", style="rounded")
                for sid in members[body]:
                    self._state(sub, self.ids[sid])  # type: ignore[arg-type]
            if k > row:  # folded: below the segment a row earlier
                graph.edge(members[bodies[k - 1 - row]][-1], body, style="invis")
        self._folded = len(bodies) > row
        if self._folded:
            for body in bodies[:row]:
                graph.edge(plan.picker.id or "", body, style="invis")

    # ------------------------------------------------------------ edges

    def draw_edges(self) -> None:
        """The transitions noted while drawing the states, each from and to a drawn node."""
        if self._folded and self.plan:
            self.graph.node(self.plan.picker.id or "", "next_step\\nruns the segment the plan names,\\nthen comes back")
        for source, target, label, tail in self.edges:
            if target not in self.ids or target in self.hidden or source in self.hidden:
                continue
            attrs = {"label": label}
            if source:
                src = self._anchor(source)
                if tail and not self._inside(target, source):
                    attrs["ltail"] = tail
            else:
                src = tail or START
            if self._segment_of:
                extra = self._segment_edge(source, target)
                if extra is None:
                    continue
                attrs.update(extra)
            if _is_compound(self.ids[target]) and not (source and self._inside(source, target)):
                attrs["lhead"] = f"cluster_{target}"
            self.graph.edge(src, self._anchor(target), **attrs)

    def _segment_edge(self, source: str, target: str) -> dict[str, str] | None:
        """How a device program's edge between ``next_step`` and a segment is drawn (None: not at all).

        The edges back to ``next_step`` do not rank; the segment's label names its runs, so the plan's
        condition is left off; once the segments fold into rows, the picture names the plan instead
        of drawing an edge to and from each segment."""
        picker = self.plan.picker.id if self.plan else None
        if target == picker and source in self._segment_of:
            return None if self._folded else {"constraint": "false"}
        if source == picker and target in self._segment_of:
            return None if self._folded else {"label": ""}
        return {}

    def _inside(self, node: str, container: str) -> bool:
        return container in self.ids and node in _subtree(self.ids[container])

    def _anchor(self, sid: str) -> str:
        """The node an edge to or from state ``sid`` is drawn at."""
        if sid not in self.ids:
            return sid
        node = _first(self.ids[sid])
        return START if node.id in self.hidden else node.id or ""


def build_graph(chart: Chart, title: str, expand: int | None = None) -> graphviz.Digraph:
    """The Graphviz graph of ``chart``; ``expand`` (a step number) draws that step's regions."""
    plan = find_plan(chart)
    graph = graphviz.Digraph(name=title)
    graph.attr(rankdir="TB" if plan else "LR", compound="true", fontname="Helvetica", label=title)
    graph.attr("node", fontname="Helvetica", fontsize="10")
    graph.attr("edge", fontname="Helvetica", fontsize="8")
    drawing = _Drawing(graph, chart, plan, expand)
    drawing.add(graph, chart)
    drawing.initial(graph, chart)
    drawing.draw_edges()
    return graph
