"""Why a process command is (not) offered, and why a step is (not) plausible, as derivation trees joining the
rule instances of ``rules/*.lp`` (ASP), the ontology axioms (OWL) and the chart states and paths (charts)."""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task, Where
from plugnproduce.errors import UnknownName
from plugnproduce.ontology.iris import local_name
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.asp import schema as s
from plugnproduce.reasoning.asp import solver
from plugnproduce.reasoning.asp.derivation import Node, asp
from plugnproduce.reasoning.asp.facts import fact_book
from plugnproduce.reasoning.asp.results import CheckResult
from plugnproduce.reasoning.asp.schema.derivations import Walk
from plugnproduce.reasoning.asp.terms import Model
from plugnproduce.reasoning.checks.branches import on_a_path, renumbered_text
from plugnproduce.reasoning.checks.offers import CELL, cell_program
from plugnproduce.reasoning.checks.plausibility import TASK, check
from plugnproduce.reasoning.explanation import counterfactuals
from plugnproduce.reasoning.explanation.axioms import Axiom, Ontology
from plugnproduce.reasoning.explanation.counterfactuals import Counterfactual

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

PROCESS_CHART = "process chart"
"""What a node of a General Process State Chart rests on, in plain words."""

DERIVATION = solver.rules("derivation")


@dataclass(frozen=True)
class Words:
    """What a sentence may name, in plain words: labels of terms, and the descriptions."""

    taxonomy: Taxonomy
    ontology: Ontology
    processes: Mapping[str, ProcessDescription]
    devices: dict[str, DeviceDescription]
    cell: str
    language: str = "en"

    def label(self, iri: str | None) -> str:
        """The label of an ontology term (``no concept`` for None)."""
        return "no concept" if iri is None else self.ontology.labels.label(iri, self.language)

    def concept(self, d: str, x: str) -> str | None:
        """The state concept a device's chart state is annotated with."""
        return next((st.concept for st in self.devices[d].states if st.id == x), None)

    def state_where(self, d: str, x: str) -> Where:
        """Where a device's chart state is written."""
        dev = self.devices[d]
        return Where(dev.chart_file, next((st.line for st in dev.states if st.id == x), None))


def axiom_node(w: Words, a: Axiom) -> Node:
    """One asserted axiom in plain words."""
    sub, sup = w.label(a.sub), w.label(a.sup)
    text = {"subclass": f"'{sub}' is a kind of '{sup}'", "equivalent": f"'{sub}' means the same as '{sup}'",
            "some": f"every '{sub}' {w.label(a.prop)} some '{sup}'",
            "defined": f"'{sub}' is defined as " + " and ".join(
                f"{w.label(p)} some '{w.label(c)}'" if p else f"'{w.label(c)}'" for p, c in a.parts)}.get(
        a.kind, f"every '{sub}' has the skill '{sup}'")
    return Node("owl", text, a.formula(), a.where)


def chain_node(w: Words, text: str, chain: tuple[Axiom, ...]) -> Node:
    """A fact the ontology entails through ``chain``: asserted when one axiom states it, else inferred."""
    if len(chain) == 1:
        return axiom_node(w, chain[0])
    detail = ", ".join(a.formula() for a in chain)
    return Node("owl", text, detail, None, True, tuple(axiom_node(w, a) for a in chain))


def subsumed(w: Words, sub: str, sup: str) -> tuple[Node, ...]:
    """Why state concept ``sub`` counts as ``sup`` (nothing when they are the same)."""
    if sub == sup:
        return ()
    chain = w.ontology.subsumption(sub, sup, w.taxonomy)
    text = f"'{w.label(sub)}' is a kind of '{w.label(sup)}'"
    if chain is None:
        return (Node("owl", text + " (the reasoner derives it; no chain of asserted axioms states it)",
                     inferred=True),)
    return (chain_node(w, text, chain),)


def skill_evidence(w: Words, dev: DeviceDescription, skill: str) -> tuple[Node, ...]:
    """Why a device has a skill: the skills its description declares, and the axioms of its classes."""
    out: list[Node] = []
    for c in dev.classes:
        chain = w.ontology.implied_skill(c, skill, w.taxonomy)
        if chain is not None:
            member = Node("owl", f"device '{dev.id}' is of the class '{w.label(c)}'",
                          f"{dev.id} : {local_name(c)}", dev.where)
            out.append(Node("owl", f"every '{w.label(c)}' has the skill '{w.label(skill)}'",
                            ", ".join(a.formula() for a in chain), None, len(chain) > 1,
                            (member, *(axiom_node(w, a) for a in chain))))
    for declared in dev.declared_skills:
        if w.taxonomy.is_a(declared, skill):
            said = Node("owl", f"the description of device '{dev.id}' says it has the skill '{w.label(declared)}'",
                        f"{dev.id} hasSkill {declared.rsplit('#', 1)[-1]}", dev.where)
            out.append(Node(said.kind, said.text, said.detail, said.where,
                            children=subsumed(w, declared, skill)) if declared != skill else said)
    return tuple(out)


def _path(dev: DeviceDescription, a: str, b: str) -> list[str] | None:
    """The transitions' targets on a shortest path from state ``a`` to ``b`` in the chart (BFS)."""
    prev: dict[str, str] = {a: a}
    queue = deque([a])
    while queue:
        x = queue.popleft()
        if x == b:
            out = [b]
            while out[-1] != a:
                out.append(prev[out[-1]])
            return out[::-1]
        for t in dev.transitions:
            if t.source == x and t.target not in prev:
                prev[t.target] = x
                queue.append(t.target)
    return None


def walk_states(w: Words, model: Model, p: str, r: str, d: str) -> list[str]:
    """The device's chart state at each region state, walking backwards from the last so each reaches the next."""
    region = w.processes[p].role(r).region
    at: dict[int, list[str]] = {}
    for a in model[Walk]:
        if (a.p, a.r, a.d) == (p, r, d):
            at.setdefault(a.i, []).append(a.x)
    seq = sorted(at.get(len(region), []))[:1]
    for i in range(len(region) - 1, 0, -1):
        paths = [(len(path), x) for x in at.get(i, []) if (path := _path(w.devices[d], x, seq[0])) is not None]
        seq.insert(0, min(paths)[1])
    return seq


def walk_node(w: Words, model: Model, p: str, r: str, d: str) -> Node:
    """How device ``d`` goes through role ``r``'s region: each region state matched to a chart state."""
    proc, dev = w.processes[p], w.devices[d]
    region, seq = proc.role(r).region, walk_states(w, model, p, r, d)
    steps: list[Node] = []
    for i, (rs, x) in enumerate(zip(region, seq, strict=True), start=1):
        concept = w.concept(d, x)
        below = [Node("chart", f"the process's state chart has role '{r}' in '{w.label(rs.concept)}' "
                               f"(state {i} of its region)", f"{proc.chart_file} state {rs.id}",
                      Where(proc.chart_file, rs.line), source=PROCESS_CHART)]
        below += subsumed(w, concept, rs.concept) if concept else []
        if i > 1:
            path = _path(dev, seq[i - 2], x) or []
            hops = " → ".join(f"'{y}'" for y in path)
            first = next((t for t in dev.transitions if path[1:] and t.source == path[0] and t.target == path[1]),
                         None)
            below.append(Node("chart", f"device '{d}' gets there from '{seq[i - 2]}': {hops}",
                              f"{dev.chart_file} path {' → '.join(path)}",
                              Where(dev.chart_file, first.line if first else None)))
        steps.append(Node("chart", f"device state '{x}' ('{w.label(concept)}') stands for the role's "
                                   f"'{w.label(rs.concept)}'", f"{dev.chart_file} state {x}",
                          w.state_where(d, x), children=tuple(below)))
    states = ", ".join(f"'{x}'" for x in seq)
    return asp("roles.lp", "walk", f"device '{d}' goes through the role's states in order: {states}",
               {"P": p, "R": r, "D": d, "I": len(seq) - 1, "X": seq[-2] if len(seq) > 1 else seq[0],
                "Y": seq[-1], "C": region[-1].concept}, tuple(steps), nth=1 if len(seq) > 1 else 0)


def play_node(w: Words, model: Model, p: str, r: str, d: str) -> Node:
    """Why device ``d`` can play role ``r`` of ``p``: its skill, and its walk through the role's states."""
    role = w.processes[p].role(r)
    skill = asp("roles.lp", "skilled", f"device '{d}' has the skill '{w.label(role.required_skill)}' that role "
                                       f"'{r}' requires", {"P": p, "R": r, "D": d, "S": role.required_skill},
                skill_evidence(w, w.devices[d], role.required_skill))
    return asp("roles.lp", "can_play", f"device '{d}' can play role '{r}' of {w.processes[p].label}",
               {"P": p, "R": r, "D": d, "N": len(role.region)}, (skill, walk_node(w, model, p, r, d)))


def derivation_model(cell: Cell, knowledge: Knowledge) -> Model:
    """The intermediate facts a derivation reads (roles.lp, offered.lp, explain.lp)."""
    return solver.solve(DERIVATION, cell_program(fact_book(knowledge), cell))


def offered_tree(w: Words, model: Model, p: str) -> Node:
    """The derivation of "``p`` is offered": one branch per role, through the devices that can play it."""
    proc = w.processes[p]
    members = set(w.devices)
    roles = []
    for role in proc.roles:
        players = sorted(a.d for a in model[s.CanPlay] if (a.p, a.r) == (p, role.name) and a.d in members)
        roles.append(asp("offered.lp", "fillable", f"role '{role.name}' can be filled by "
                                                   + " or ".join(f"device '{d}'" for d in players),
                         {"C": CELL, "P": p, "R": role.name, "D": players[0]},
                         tuple(play_node(w, model, p, role.name, d) for d in players)))
    return asp("offered.lp", "offered", f"{proc.label} is offered in cell '{w.cell}': every role can be filled",
               {"C": CELL, "P": p}, tuple(roles))


def _skills_of(w: Words, d: str) -> str:
    dev = w.devices[d]
    return ", ".join(f"'{w.label(x)}'" for x in sorted(dev.skills)) or "none"


def not_offered_tree(w: Words, model: Model, p: str) -> Node:
    """The derivation of "``p`` is not offered": each reason explain.lp finds, with its evidence."""
    proc = w.processes[p]
    reasons: list[Node] = []
    for a in sorted(model[s.NoSkill], key=lambda a: a.r):
        if a.p != p:
            continue
        role = proc.role(a.r)
        need = Node("owl", f"role '{a.r}' of {proc.label} requires the skill '{w.label(a.s)}'",
                    f"{role.iri} requiresSkill {a.s.rsplit('#', 1)[-1]}", role.where)
        have = tuple(Node("owl", f"device '{d}' has the skills {_skills_of(w, d)}", "", w.devices[d].where)
                     for d in sorted(w.devices))
        reasons.append(asp("explain.lp", "no_skill", f"no device in cell '{w.cell}' has the skill "
                                                     f"'{w.label(a.s)}' that role '{a.r}' requires",
                           {"C": CELL, "P": p, "R": a.r, "S": a.s}, (need, *have)))
    for b in sorted(model[s.LacksState], key=lambda a: (a.r, a.d, a.i)):
        if b.p != p:
            continue
        dev = w.devices[b.d]
        rs = proc.role(b.r).region[b.i - 1]
        states = ", ".join(f"'{st.id}' ('{w.label(st.concept)}')" for st in dev.states)
        reasons.append(asp("explain.lp", "lacks_state", f"device '{b.d}' has the skill, but its state chart has "
                                                        f"no state that is '{w.label(b.con)}'",
                           {"C": CELL, "P": p, "R": b.r, "D": b.d, "I": b.i, "K": b.con},
                           (Node("chart", f"role '{b.r}' goes through '{w.label(b.con)}'",
                                 f"{proc.chart_file} state {rs.id}", Where(proc.chart_file, rs.line),
                                 source=PROCESS_CHART),
                            Node("chart", f"device '{b.d}' has the states {states}", dev.chart_file,
                                 Where(dev.chart_file)))))
    for c in sorted(model[s.Unreachable], key=lambda a: (a.r, a.d, a.i, a.x)):
        if c.p != p:
            continue
        rs = proc.role(c.r).region[c.i]
        reasons.append(asp("explain.lp", "unreachable", f"device '{c.d}' cannot get from state '{c.x}' to a "
                                                        f"state that is '{w.label(c.con)}', where role '{c.r}' "
                                                        f"goes next", {"C": CELL, "P": p, "R": c.r, "D": c.d,
                                                                      "I": c.i, "X": c.x, "K": c.con},
                           (Node("chart", f"role '{c.r}' goes to '{w.label(c.con)}' next",
                                 f"{proc.chart_file} state {rs.id}", Where(proc.chart_file, rs.line),
                                 source=PROCESS_CHART),
                            Node("chart", f"no path in the state chart of '{c.d}' leads from '{c.x}' there",
                                 f"{w.devices[c.d].chart_file} state {c.x}", w.state_where(c.d, c.x)))))
    return Node("answer", f"{proc.label} is not offered in cell '{w.cell}': some role cannot be filled",
                f"not offered({CELL},{p})", proc.where,
                children=tuple(dataclasses.replace(n, fails=True) for n in reasons))


def _left_by(result: CheckResult, n: int, d: str) -> int:
    return max((j for j in range(1, n) if d in result.steps[j - 1].bindings.values()), default=0)


def _since(result: CheckResult, n: int, d: str) -> Node:
    j = _left_by(result, n, d)
    x = result.steps[n - 1].states.get(d, "?")
    text = (f"device '{d}' starts in state '{x}' (its initial state)" if j == 0 else
            f"step {j} ({result.steps[j - 1].command}) left device '{d}' in state '{x}'")
    return asp("provenance.lp", "left_by", text, {"C": CELL, "T": TASK, "I": n - 1 if j else 1, "D": d, "J": j},
               nth=0 if j == 0 else 1)


def device_at_step(w: Words, result: CheckResult, task: Task, n: int, r: str, d: str) -> Node:
    """Device ``d``'s state when step ``n`` starts, where it came from, and whether role ``r`` may start there."""
    step = result.steps[n - 1]
    x = step.states.get(d, "?")
    concept = w.concept(d, x)
    proc = w.processes.get(step.command)
    need = proc.role(r).start_concept if proc else None
    ok = need is not None and concept is not None and w.taxonomy.is_a(concept, need)
    below: list[Node] = [_since(result, n, d)]
    if proc is not None and need is not None:
        rs = proc.role(r).region[0]
        below.append(Node("chart", f"role '{r}' of {proc.label} starts '{w.label(need)}'",
                          f"{proc.chart_file} state {rs.id}", Where(proc.chart_file, rs.line), source=PROCESS_CHART))
        if ok and concept is not None:
            below += subsumed(w, concept, need)
        elif concept is not None:
            below.append(Node("owl", f"'{w.label(concept)}' is not a kind of '{w.label(need)}'",
                              f"{local_name(concept)} ⋢ {local_name(need)}", inferred=True))
    verdict = "" if need is None else (f", which role '{r}' may start from" if ok else
                                       f"; role '{r}' needs it '{w.label(need)}'")
    return Node("chart", f"device '{d}' is in state '{x}' ('{w.label(concept)}'){verdict}",
                f"{w.devices[d].chart_file} state {x}" if d in w.devices else "",
                w.state_where(d, x) if d in w.devices else None, children=tuple(below))


def step_tree(w: Words, result: CheckResult, task: Task, n: int) -> Node:
    """The derivation of "step ``n`` is (not) plausible": each device it uses, and each problem found."""
    step = result.steps[n - 1]
    problems = [p for p in result.problems if p.step == n]
    children: list[Node] = []
    for p in problems:
        if p.kind == "wrong_state" and p.device and p.role:
            children.append(asp("chain.lp", "wrong_state", f"device '{p.device}' is not in a state role "
                                                           f"'{p.role}' may start from",
                                {"C": CELL, "T": TASK, "I": n, "R": p.role, "D": p.device, "X": p.state,
                                 "P": step.command, "K": p.needed},
                                (device_at_step(w, result, task, n, p.role, p.device),), fails=True))
        else:
            children.append(Node("answer", p.reason.plain, p.reason.text, p.where, fails=True,
                                 children=tuple(Node("chart", "the problem rests on this line", str(x), x,
                                                     source="description") for x in p.reason.where)))
    troubled = {p.device for p in problems}
    children += [device_at_step(w, result, task, n, r, d) for r, d in step.bindings.items() if d not in troubled]
    verdict = "is not plausible" if problems else "is plausible: every device it uses is where it may start"
    where = task.where(task.steps[n - 1]) if 1 <= n <= len(task.steps) else None
    return Node("answer", f"step {n} ({step.command}) {verdict}", "", where, children=tuple(children))


@dataclass(frozen=True)
class Explanation:
    """An answer of the reasoner, its derivation, and the counterfactuals that would turn it around."""

    question: str
    """``offered`` (is a process command offered?) or ``plausible`` (is a step plausible?)."""
    subject: str
    answer: bool
    derivation: Node
    counterfactuals: tuple[Counterfactual, ...] = ()
    none_exists: str | None = None
    """When no counterfactual exists (or none could be confirmed): a sentence that says so."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"question": self.question, "subject": self.subject, "answer": self.answer,
                "derivation": self.derivation.to_json(),
                "counterfactuals": [c.to_json() for c in self.counterfactuals], "none_exists": self.none_exists}


def words(cell: Cell, knowledge: Knowledge, ontology: Ontology, language: str = "en") -> Words:
    """What sentences about ``cell`` may name."""
    return Words(knowledge.taxonomy, ontology, knowledge.processes_by_id, {d.id: d for d in cell.devices}, cell.name,
                 language)


def explain_offered(command: str, cell: Cell, knowledge: Knowledge, ontology: Ontology,
                    catalogue: Sequence[DeviceDescription], language: str = "en") -> Explanation:
    """Why ``command`` is (not) offered in ``cell``: the derivation, and the confirmed counterfactuals — devices
    to add or swap in for a "no", the devices a "yes" rests on."""
    if command not in knowledge.processes_by_id:
        raise UnknownName("process command", command, knowledge.processes_by_id)
    w = words(cell, knowledge, ontology, language)
    model = derivation_model(cell, knowledge)
    if any(a.p == command for a in model[s.Offered]):
        flips = counterfactuals.make_not_offered(command, cell, knowledge)
        return Explanation("offered", command, True, offered_tree(w, model, command), tuple(flips),
                           None if flips else f"no single device of the cell is needed for {command}: "
                                              f"another can stand in for each")
    fixes = counterfactuals.make_offered(command, cell, catalogue, knowledge)
    return Explanation("offered", command, False, not_offered_tree(w, model, command), tuple(fixes),
                       None if fixes else f"no device of the catalogue, added alone or in pairs or swapped in, "
                                          f"makes the cell offer {command}")


def explain_plausible(task: Task, n: int, cell: Cell, knowledge: Knowledge, ontology: Ontology,
                      language: str = "en") -> Explanation:
    """Why step ``n`` of ``task`` is (not) plausible: the derivation, and for a "no" the confirmed states its
    devices would have to be in (the service adds the repairs, with their side effects, from
    :func:`sideeffects.assess`)."""
    if not 1 <= n <= len(task.steps):
        raise UnknownName("step", n, detail=f"the task has steps 1 to {len(task.steps)}")
    if task.branches:  # along the path that makes the step (not) plausible, numbered as the task numbers it
        straight, positions = on_a_path(task, n, knowledge, lambda t: check(t, cell, knowledge))
        ex = explain_plausible(straight, positions.index(n) + 1, cell, knowledge, ontology, language)
        return _renumbered(ex, positions, task.path(n))
    result = check(task, cell, knowledge)
    w = words(cell, knowledge, ontology, language)
    tree = step_tree(w, result, task, n)
    ok = not any(p.step == n for p in result.problems)
    if ok:
        return Explanation("plausible", f"step {n}", True, tree)
    states = counterfactuals.needed_states(result, task, n, cell, knowledge)
    return Explanation("plausible", f"step {n}", False, tree, tuple(states),
                       None if states else f"no state of its devices alone makes step {n} plausible; "
                                           f"see the repairs")


def _renumbered(ex: Explanation, positions: tuple[int, ...], path: str | None) -> Explanation:
    """An explanation found on a straight path, with the task's step numbers and the step's path named."""
    def node(n: Node) -> Node:
        return dataclasses.replace(n, text=renumbered_text(n.text, positions),
                                   detail=renumbered_text(n.detail, positions), children=tuple(map(node, n.children)))

    flips = tuple(dataclasses.replace(c, text=renumbered_text(c.text, positions),
                                      step=positions[c.step - 1] if c.step and c.step <= len(positions) else c.step)
                  for c in ex.counterfactuals)
    subject = renumbered_text(ex.subject, positions) + (f" ({path})" if path else "")
    none = renumbered_text(ex.none_exists, positions) if ex.none_exists else None
    return dataclasses.replace(ex, subject=subject, derivation=node(ex.derivation), counterfactuals=flips,
                               none_exists=none)
