"""Derivation trees: an answer of the reasoner and the evidence it rests on, as nested nodes of three kinds —
OWL (an axiom, asserted or inferred by HermiT), ASP (a rule instance of ``rules/*.lp``) and chart (a state,
transition or path of a Device or General Process State Chart) — each with a sentence in plain words, an
engineer's detail (axiom, ground rule, IRIs) and the ``file:line`` it rests on."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cache

from plugnproduce.description.model import Where
from plugnproduce.reasoning.asp import solver
from plugnproduce.resources import rules_path

KINDS = ("answer", "owl", "asp", "chart", "task")
"""Kinds of node: the answer itself, and the three kinds of evidence (plus a step of the task)."""

SOURCE_WORDS = {"answer": "finding", "owl": "ontology", "asp": "rule", "chart": "device chart", "task": "task"}
"""What a node rests on, in plain words, by kind (a process's chart says so itself: ``source``)."""


@dataclass(frozen=True)
class Node:
    """One node of a derivation: a sentence, and the evidence below it."""

    kind: str
    text: str
    """The sentence in plain words: labels, no IRIs, no ``file:line``."""
    detail: str = ""
    """The engineer's view: the axiom (DL notation), the ground rule, the state ids."""
    where: Where | None = None
    inferred: bool = False
    """OWL: whether the reasoner inferred the fact (no single asserted axiom states it)."""
    children: tuple[Node, ...] = field(default=())
    source: str = ""
    """What the node rests on in plain words ("process chart"); default: by kind (:data:`SOURCE_WORDS`)."""
    fails: bool = False
    """The node is a reason the answer is no: the failing branch, not a fact that holds."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict (nested)."""
        out: dict[str, object] = {"kind": self.kind, "source": self.source or SOURCE_WORDS.get(self.kind, self.kind),
                                  "text": self.text}
        if self.fails:
            out["fails"] = True
        if self.detail:
            out["detail"] = self.detail
        if self.where is not None:
            out["where"] = str(self.where)
        if self.kind == "owl":
            out["inferred"] = self.inferred
        out["children"] = [c.to_json() for c in self.children]
        return out

    def walk(self) -> list[Node]:
        """This node and every node below it, depth first."""
        return [self, *(n for c in self.children for n in c.walk())]

    def sentences(self, depth: int | None = None, verbose: bool = False) -> list[tuple[int, str]]:
        """(level, sentence) pairs depth first, so the deepest cause of each branch comes last; nodes below
        ``depth`` are left out. ``verbose`` adds the detail and ``file:line`` (the engineer's view)."""
        text = self.text
        if verbose:
            extra = [x for x in (self.detail, str(self.where) if self.where else "") if x]
            text += f" [{'; '.join(extra)}]" if extra else ""
            text += " (inferred by HermiT)" if self.kind == "owl" and self.inferred else ""
        out = [(0, text)]
        if depth is None or depth > 0:
            nxt = None if depth is None else depth - 1
            out += [(level + 1, s) for c in self.children for level, s in c.sentences(nxt, verbose)]
        return out


_VAR = re.compile(r"\b[A-Z][A-Za-z0-9_]*\b")
_SUM = re.compile(r"\b(\d+)\+(\d+)\b")


@dataclass(frozen=True)
class Rule:
    """A rule of an encoding: its file, first line and text."""

    file: str
    line: int
    text: str

    def where(self) -> Where:
        """Where the rule is written."""
        return Where(str(rules_path() / self.file), self.line)

    def instance(self, values: dict[str, object]) -> str:
        """The rule with variables replaced by ``values`` (ASP strings quoted; others left as variables)."""
        def sub(m: re.Match[str]) -> str:
            v = values.get(m.group(0))
            if v is None:
                return m.group(0)
            return str(v) if isinstance(v, int) else f'"{v}"'
        text = _VAR.sub(sub, self.text)
        return _SUM.sub(lambda m: str(int(m.group(1)) + int(m.group(2))), text)


@cache
def rule(file: str, head: str, nth: int = 0) -> Rule:
    """The ``nth`` rule of encoding ``file`` whose head is predicate ``head``."""
    lines = solver.encoding(file).splitlines()
    found = 0
    for n, text in enumerate(lines):
        if re.match(rf"^{re.escape(head)}\(", text):
            if found == nth:
                body = [text.strip()]
                m = n
                while not body[-1].endswith(".") and m + 1 < len(lines):
                    m += 1
                    body.append(lines[m].strip())
                return Rule(file, n + 1, " ".join(body))
            found += 1
    raise LookupError(f"no rule for {head} in {file}")


def asp(file: str, head: str, text: str, values: dict[str, object], children: tuple[Node, ...] = (),
        nth: int = 0, fails: bool = False) -> Node:
    """An ASP evidence node: the rule instance of ``head`` in ``file`` that derives the fact ``text`` states
    (``fails``: a reason the answer is no)."""
    r = rule(file, head, nth)
    return Node("asp", text, r.instance(values), r.where(), children=children, fails=fails)
