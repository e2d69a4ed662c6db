"""The only module that touches clingo's ``Control``: load encodings, ground, solve.

Encodings are read from ``rules/`` (package data, :func:`plugnproduce.resources.rules_path`)
once per process. Programs with no choice are grounded and solved once (one model);
repairs are optimised, then the next-best distinct ones are found in the same ``Control``
by forbidding each found edit set (multi-shot).

A large program is grounded and solved in a thread of its own (:data:`APART`). What clingo frees after
a long task's check leaves the C allocator's free lists long and scattered; in the thread that made
them, every ``Control`` after it spends its time searching them: the windows ``pnp repair`` solves after
the check of a 10,000-step task took twice their time, half of it in ``malloc``. A thread of its own
allocates from an arena of its own (glibc), so the small programs that follow find the main one tidy.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Hashable, Iterable, Iterator, Sequence
from functools import cache, lru_cache
from typing import TypeVar

import clingo
import clingo.ast

from plugnproduce.errors import EncodingError
from plugnproduce.reasoning.asp.terms import Model, decode
from plugnproduce.resources import rules_path

T = TypeVar("T")

PROGRAMS: dict[str, tuple[tuple[str, ...], str]] = {
    "capabilities": (("roles.lp", "offered.lp", "explain.lp"), "show_capabilities.lp"),
    "bindings": (("roles.lp", "offered.lp", "bindings.lp", "explain.lp"), "show_capabilities.lp"),
    "offered": (("roles.lp", "offered.lp"), "show_capabilities.lp"),
    "check": (("roles.lp", "resolve.lp", "chain.lp", "params.lp", "provenance.lp"), "show_check.lp"),
    "abilities": (("roles.lp", "params.lp"), "show_abilities.lp"),
    "repair": (("roles.lp", "chain.lp", "params.lp", "repair.lp"), "show_repair.lp"),
    "window": (("roles.lp", "chain.lp", "params.lp", "repair.lp", "window.lp"), "show_window.lp"),
    "derivation": (("roles.lp", "offered.lp", "explain.lp"), "show_derivation.lp"),
    "plan": (("roles.lp", "offered.lp", "plan.lp"), "show_plan.lp"),
}
"""The one list of what makes each program: its encodings by concern, then the file that says what it shows."""


def rules(program: str, *, show: bool = True) -> tuple[str, ...]:
    """The encodings of a program of :data:`PROGRAMS`, with its ``#show`` file unless ``show`` is False."""
    concerns, shown = PROGRAMS[program]
    return concerns + (shown,) if show else concerns


CAPABILITIES, BINDINGS, OFFERED, CHECK, ABILITIES, REPAIR, WINDOW, PLAN = (
    rules(p) for p in ("capabilities", "bindings", "offered", "check", "abilities", "repair", "window", "plan"))

SOLVED = 4
"""How many answers of :func:`solve` a process keeps (the programs of the last few checks)."""

APART = 100_000
"""Facts (characters) from which :func:`solve` grounds and solves in a thread of its own (a check of some 1,000
steps); a smaller program is not worth a thread's start."""

OPTIMISE = ("--opt-strategy=usc,disjoint",)
"""Core-guided optimisation: default branch-and-bound is unstable on these programs."""


@cache
def encoding(name: str) -> str:
    """The text of one encoding file in ``rules/``."""
    path = rules_path() / name
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise EncodingError(f"encoding {name} not found in {rules_path()}") from exc


@lru_cache(maxsize=16)
def _parsed(texts: tuple[str, ...]) -> tuple[clingo.ast.AST, ...]:
    """The statements of encodings, each text parsed once a process (a long task's repair makes a ``Control`` per
    window: added as parsed statements, the program is the one their text gives, without parsing it again). Keyed
    by the texts themselves, so an encoding read again with other text is parsed again. A text clingo refuses
    raises RuntimeError with clingo's error messages."""
    statements: list[clingo.ast.AST] = []
    messages: list[str] = []

    def log(code: clingo.MessageCode, message: str) -> None:
        messages.append(message.strip())

    try:
        for text in texts:
            clingo.ast.parse_string(text, statements.append, logger=log, message_limit=50)
    except RuntimeError as exc:
        raise RuntimeError("; ".join(m for m in messages if "error" in m) or str(exc)) from exc
    return tuple(statements)


def _control(arguments: Sequence[str]) -> tuple[clingo.Control, list[str]]:
    messages: list[str] = []

    def log(code: clingo.MessageCode, message: str) -> None:
        messages.append(message.strip())

    return clingo.Control(list(arguments), logger=log, message_limit=50), messages


def _ground(ctl: clingo.Control, messages: list[str], rules: Sequence[str], facts: str) -> None:
    try:
        with clingo.ast.ProgramBuilder(ctl) as builder:
            for statement in _parsed(tuple(encoding(name) for name in rules)):
                builder.add(statement)
        ctl.add("base", [], facts)
        ctl.ground([("base", [])])
    except RuntimeError as exc:
        detail = "; ".join(m for m in messages if "error" in m) or str(exc)
        raise EncodingError(f"clingo could not ground {', '.join(rules)}: {detail}") from exc


def solve(rules: Sequence[str], facts: str) -> Model:
    """The one model of a program that needs no search (stratified encodings plus facts); the same program asked
    again in a process is answered from the last few answers (``pnp repair`` checks a task, then reads the same
    check's states to cut the task into windows). The model is shared: read it, never change it."""
    return _solved(tuple(rules), facts)


@lru_cache(maxsize=SOLVED)
def _solved(rules: tuple[str, ...], facts: str) -> Model:
    return _apart(lambda: _one_model(rules, facts)) if len(facts) >= APART else _one_model(rules, facts)


def _apart(work: Callable[[], T]) -> T:
    """``work()`` done in a thread of its own (see the module's docstring): its answer, or its exception raised
    here."""
    answer: list[T] = []
    failed: list[BaseException] = []

    def run() -> None:
        try:
            answer.append(work())
        except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread, raised there
            failed.append(exc)

    worker = threading.Thread(target=run, name="pnp-solve", daemon=True)
    worker.start()
    worker.join()
    if failed:
        raise failed[0]
    return answer[0]


def _one_model(rules: tuple[str, ...], facts: str) -> Model:
    ctl, messages = _control(["--warn=none"])
    _ground(ctl, messages, rules, facts)
    found: list[Model] = []
    result = ctl.solve(on_model=lambda m: found.append(decode(m.symbols(shown=True))))
    if not result.satisfiable or not found:
        raise EncodingError(f"{', '.join(rules)} has no model for these facts; stratified encodings always have one")
    return found[-1]


def optimise(
    rules: Sequence[str],
    facts: str,
    top: int,
    forbid: Callable[[Model], str],
    same: Callable[[Model], Hashable] | None = None,
    arguments: Sequence[str] = OPTIMISE,
) -> list[Model]:
    """Up to ``top`` optimal models, each optimal once the ones before it are forbidden.

    ``forbid`` turns a model into an integrity constraint (ASP text) that rules it, and
    every model containing it, out; it is added as a new program part of the same Control.
    A model whose ``same`` key equals an earlier one's (another way to the same result)
    is forbidden too but not returned; at most ``2 * top`` such extra solves are made.
    """
    ctl, messages = _control(["--warn=none", *arguments])
    _ground(ctl, messages, rules, facts)
    models: list[Model] = []
    seen: set[Hashable] = set()
    for k in range(3 * top):
        best = _optimum(ctl)
        if best is None:
            break
        key = same(best) if same is not None else k
        if key not in seen:
            seen.add(key)
            models.append(best)
        if len(models) == top:
            break
        part = f"forbid{k}"
        ctl.add(part, [], forbid(best))
        ctl.ground([(part, [])])
    return models


def grow(rules: Sequence[str], facts: str, horizons: Iterable[int],
         arguments: Sequence[str] = OPTIMISE) -> Iterator[tuple[int, Model | None]]:
    """Incremental solving, the horizon growing one step at a time: for each horizon, the optimal model or None.

    The encodings have program parts ``step(t)`` (what one more step adds) and ``check(t)`` (the goal at
    horizon t, active while the external ``query(t)`` is true); each horizon grounds only its own parts.
    """
    ctl, messages = _control(["--warn=none", *arguments])
    _ground(ctl, messages, rules, facts)
    for t in _grown(ctl, horizons):
        yield t, _optimum(ctl)


def grow_optima(rules: Sequence[str], facts: str, horizons: Iterable[int], most: int,
                arguments: Sequence[str] = OPTIMISE) -> Iterator[tuple[int, list[Model]]]:
    """:func:`grow`, but for each horizon up to ``most`` of its optimal models (clingo's ``optN``), in the order
    clingo finds them: the plans a further criterion (their cycle time) chooses among."""
    ctl, messages = _control(["--warn=none", "--opt-mode=optN", f"--models={most}", *arguments])
    _ground(ctl, messages, rules, facts)
    for t in _grown(ctl, horizons):
        yield t, _optima(ctl)


def _grown(ctl: clingo.Control, horizons: Iterable[int]) -> Iterator[int]:
    """Each horizon in turn, its parts ``step(t)`` and ``check(t)`` grounded and only its ``query(t)`` true."""
    before = None
    for t in horizons:
        ctl.ground([("step", [clingo.Number(t)]), ("check", [clingo.Number(t)])])
        if before is not None:
            ctl.release_external(before)
        before = clingo.Function("query", [clingo.Number(t)])
        ctl.assign_external(before, True)
        yield t


def _optima(ctl: clingo.Control) -> list[Model]:
    """The models of an ``optN`` solve that are proven optimal."""
    found: list[Model] = []

    def keep(m: clingo.Model) -> None:
        if m.optimality_proven:
            found.append(decode(m.symbols(shown=True), m.cost))

    ctl.solve(on_model=keep)
    return found


def _optimum(ctl: clingo.Control) -> Model | None:
    """The last (optimal) model of an optimising solve, or None if there is none."""
    found: list[Model] = []
    result = ctl.solve(on_model=lambda m: found.append(decode(m.symbols(shown=True), m.cost)))
    return found[-1] if result.satisfiable and found else None
