"""Mutation testing of the ASP encodings (``rules/*.lp``), which mutmut cannot read.

Each statement of an encoding is changed in three ways, one change per mutant:

- *delete rule*: the statement (rule, constraint, choice rule, optimisation, ``#show``) is removed;
- *drop literal*: one literal of its body is removed (``a :- b, c.`` → ``a :- c.``);
- *flip comparison*: one comparison of its body is turned (``<`` ↔ ``<=``, ``>`` ↔ ``>=``, ``=`` ↔ ``!=``).

A changed statement is written on one line followed by as many empty lines as it had, so that every
other rule keeps its line (answers name rules by ``file:line``). A mutant clingo refuses (a variable
left unsafe, an empty body) is *refused*: no test needs to kill it, and it is counted apart. The
others are run against the reasoning tests named for the file (``-x``: the first failure kills).
``#defined`` is not changed: it only silences a warning the reasoner turns off.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Collection, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

import clingo

FLIPS = {"<": "<=", "<=": "<", ">": ">=", ">=": ">", "=": "!=", "!=": "=", "==": "!="}
_COMPARISON = re.compile(r"<=|>=|!=|==|<|>|=")
_OPEN, _CLOSE = "({[", ")}]"
COPIED = ("src", "tests", "ontology", "rules", "descriptions")


@dataclass(frozen=True)
class Statement:
    """One statement of an encoding: where it starts and its text up to and with its final dot."""

    line: int
    start: int
    end: int
    text: str


@dataclass(frozen=True)
class Mutant:
    """One changed statement of an encoding."""

    file: str
    line: int
    kind: str
    before: str
    after: str

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"


def _skip_comment(text: str, i: int) -> int:
    """The offset after the comment starting at ``i`` (``%`` to the end of the line, or ``%* ... *%``)."""
    if text.startswith("%*", i):
        end = text.find("*%", i + 2)
        return len(text) if end < 0 else end + 2
    end = text.find("\n", i)
    return len(text) if end < 0 else end


def _skip_string(text: str, i: int) -> int:
    """The offset after the string literal starting at ``i``."""
    i += 1
    while i < len(text) and text[i] != '"':
        i += 2 if text[i] == "\\" else 1
    return i + 1


def statements(text: str) -> list[Statement]:
    """The statements of an encoding, in order (comments and blank space between them left out)."""
    found: list[Statement] = []
    start: int | None = None
    i = 0
    while i < len(text):
        c = text[i]
        if c == "%":
            i = _skip_comment(text, i)
            continue
        if start is None and not c.isspace():
            start = i
        if c == '"':
            i = _skip_string(text, i)
            continue
        if c == "." and start is not None and text[i - 1] != "." and not text.startswith("..", i):
            found.append(Statement(text.count("\n", 0, start) + 1, start, i + 1, text[start:i + 1]))
            start = None
        i += 1
    return found


def _top_level(text: str) -> Iterator[tuple[int, str]]:
    """Each character of ``text`` outside brackets and strings, with its offset."""
    depth = 0
    i = 0
    while i < len(text):
        c = text[i]
        if c == '"':
            i = _skip_string(text, i)
            continue
        if c in _OPEN:
            depth += 1
        elif c in _CLOSE:
            depth -= 1
        elif depth == 0:
            yield i, c
        i += 1


def split_rule(text: str) -> tuple[str, list[str]] | None:
    """The head and the body literals of a rule or constraint (``None`` for a fact or a directive)."""
    if text.startswith("#"):
        return None
    body = text[:-1]
    neck = next((i for i, c in _top_level(body) if c == ":" and body.startswith(":-", i)), None)
    if neck is None:
        return None
    head, rest = body[:neck].strip(), body[neck + 2:]
    literals: list[str] = []
    last = 0
    for i, c in _top_level(rest):
        if c == ",":
            literals.append(rest[last:i].strip())
            last = i + 1
    literals.append(rest[last:].strip())
    return head, literals


def _joined(head: str, literals: list[str]) -> str:
    return (head + " " if head else "") + ":- " + ", ".join(literals) + "."


def _flips(literal: str) -> Iterator[str]:
    """The literal with each of its top-level comparisons turned, one at a time."""
    for i, _ in _top_level(literal):
        if i > 0 and literal[i - 1] in "<>!=":
            continue
        match = _COMPARISON.match(literal, i)
        if match and not literal.startswith(":-", i - 1):
            op = match.group()
            yield literal[:i] + FLIPS[op] + literal[match.end():]


def _one_line(text: str) -> str:
    return " ".join(text.split())


def changes(statement: Statement) -> Iterator[tuple[str, str]]:
    """(kind, changed statement) for every mutant of one statement; deletion gives an empty text."""
    if statement.text.startswith("#defined"):
        return
    yield "delete rule", ""
    parts = split_rule(statement.text)
    if parts is None:
        return
    head, literals = parts
    for k in range(len(literals)):
        yield "drop literal", _joined(head, literals[:k] + literals[k + 1:])
    for k, literal in enumerate(literals):
        for flipped in _flips(literal):
            yield "flip comparison", _joined(head, [*literals[:k], flipped, *literals[k + 1:]])


def mutants(file: str, text: str) -> Iterator[tuple[Mutant, str]]:
    """Every mutant of an encoding, with the whole changed text of its file (line numbers kept)."""
    for s in statements(text):
        for kind, changed in changes(s):
            padded = _one_line(changed) + "\n" * s.text.count("\n")
            yield (Mutant(file, s.line, kind, _one_line(s.text), _one_line(changed) or "(deleted)"),
                   text[:s.start] + padded + text[s.end:])


def refused(text: str) -> bool:
    """Whether clingo refuses the encoding on its own (a syntax error, an unsafe variable)."""
    ctl = clingo.Control(["--warn=none"], logger=lambda code, message: None)
    try:
        ctl.add("base", [], text)
        ctl.ground([("base", [])])
    except RuntimeError:
        return True
    return False


# ---- running the tests


@dataclass(frozen=True)
class Target:
    """One encoding and the reasoning tests that cover it, fastest killers first."""

    name: str
    file: str
    tests: tuple[str, ...]


def _copy(root: Path, slot: Path) -> None:
    if slot.exists():
        shutil.rmtree(slot)
    slot.mkdir(parents=True)
    for name in COPIED:
        shutil.copytree(root / name, slot / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    shutil.copy2(root / "pyproject.toml", slot / "pyproject.toml")


def _pytest(slot: Path, tests: tuple[str, ...], timeout: float | None) -> tuple[str, float]:
    """Run the tests in a work copy: killed (a test failed), survived, timeout; and the seconds taken."""
    env = {**os.environ, "PYTHONPATH": f"{slot / 'src'}{os.pathsep}{slot}", "PYTHONDONTWRITEBYTECODE": "1"}
    command = [sys.executable, "-m", "pytest", "-x", "-q", "-n", "0", "-p", "no:cacheprovider", "-p", "no:randomly",
               *tests]
    started = time.monotonic()
    try:
        done = subprocess.run(command, cwd=slot, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.monotonic() - started
    seconds = time.monotonic() - started
    if done.returncode == 0:
        return "survived", seconds
    if done.returncode in (1, 2, 3):
        return "killed", seconds
    tail = " / ".join((done.stdout + done.stderr).strip().splitlines()[-3:])
    raise RuntimeError(f"pytest exit {done.returncode} in {slot}: {tail}")


def _load(path: Path) -> dict[str, str]:
    return json.loads(path.read_text(encoding="utf-8")) if path.exists() else {}


def _key(m: Mutant) -> str:
    return json.dumps(asdict(m), sort_keys=True)


def run_target(target: Target, root: Path, work: Path, jobs: int, again: bool = False,
               listed: Collection[tuple[str, str, str]] = ()) -> dict[str, tuple[Mutant, str]]:
    """Test every mutant of one encoding (``again``: only the last run's survivors); the status of each.

    A mutant ``listed`` as equivalent (by file, before, after) is not run: it is taken to survive.
    """
    original = (root / target.file).read_text(encoding="utf-8")
    record = work / "results.json"
    previous = _load(record) if again else {}
    slots = [work / f"slot{k}" for k in range(jobs)]
    for slot in slots:
        _copy(root, slot)
    status, baseline = _pytest(slots[0], target.tests, None)
    if status != "survived":
        raise RuntimeError(f"the tests of {target.name} fail without a mutant: {' '.join(target.tests)}")
    timeout = 3 * baseline + 10
    results: dict[str, tuple[Mutant, str]] = {}
    pending: list[tuple[Mutant, str]] = []
    for mutant, text in mutants(target.file, original):
        key = _key(mutant)
        if refused(text):
            results[key] = (mutant, "refused")
        elif (mutant.file, mutant.before, mutant.after) in listed:
            results[key] = (mutant, "survived")
        elif again and previous.get(key) not in (None, "survived"):
            results[key] = (mutant, previous[key])
        else:
            pending.append((mutant, text))
    free = list(slots)

    def test(item: tuple[Mutant, str]) -> tuple[Mutant, str]:
        slot = free.pop()
        try:
            (slot / target.file).write_text(item[1], encoding="utf-8")
            return item[0], _pytest(slot, target.tests, timeout)[0]
        finally:
            (slot / target.file).write_text(original, encoding="utf-8")
            free.append(slot)

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for done, (mutant, outcome) in enumerate(pool.map(test, pending), start=1):
            results[_key(mutant)] = (mutant, outcome)
            print(f"{target.name}: {done} of {len(pending)} mutants tested", file=sys.stderr, flush=True)
            record.write_text(json.dumps({k: v[1] for k, v in results.items()}, indent=1), encoding="utf-8")
    return results


def report(target: Target, results: dict[str, tuple[Mutant, str]], known: dict[tuple[str, str, str], str],
           seconds: float) -> Counter[str]:
    """Print the figures of one encoding and each survivor at its ``file:line``; the counts."""
    counts: Counter[str] = Counter()
    lines: list[str] = []
    for mutant, outcome in sorted(results.values(), key=lambda r: (r[0].line, r[0].kind, r[0].after)):
        if outcome == "refused":
            counts["refused"] += 1
            continue
        counts["mutants"] += 1
        if outcome != "survived":
            counts["killed" if outcome == "killed" else "timeouts"] += 1
            continue
        why = known.get((mutant.file, mutant.before, mutant.after))
        counts["equivalent" if why else "survived"] += 1
        lines.append(f"  {'equivalent' if why else 'survived'}: {mutant.where}: {mutant.kind}: {mutant.before}  ->  "
                     f"{mutant.after}" + (f"  ({why})" if why else ""))
    print(f"{target.name}: {counts['mutants']} mutants, {counts['killed']} killed, {counts['survived']} survived, "
          f"{counts['timeouts']} timeouts, {counts['equivalent']} equivalent, {counts['refused']} refused by clingo "
          f"({seconds:.0f} s; {target.file})", flush=True)
    for line in lines:
        print(line, flush=True)
    return counts
