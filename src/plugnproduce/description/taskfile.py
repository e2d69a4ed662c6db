"""Task files (YAML) → :class:`~plugnproduce.description.model.Task`, and back: the one task reader and writer.

Steps, loops and branches nest in the file; the task holds them flattened
(:mod:`plugnproduce.description.flow`): a loop's body twice, a branch's steps right
after the step whose outcome decides. Every error names the file and line.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from plugnproduce.description.flow import Branch, Loop, outermost_first
from plugnproduce.description.model import Link, Step, Task, plain_value
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.ontology.iris import concept_iri, concept_value
from plugnproduce.safeio import PlainDumper, parse_yaml_bytes, read_bytes

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")
_OUTCOME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}|https?://[^\s#<>\"]{1,200}#[A-Za-z][A-Za-z0-9_]{0,63}")
"""An outcome: the local name of a ``pnp`` concept, or the full IRI of a library's own."""


def _mapping(node: yaml.Node, path: Path, what: str) -> dict[str, yaml.Node]:
    if not isinstance(node, yaml.MappingNode):
        raise DescriptionError(f"{what} must be a mapping", path, node.start_mark.line + 1)
    out: dict[str, yaml.Node] = {}
    for k, v in node.value:
        if not isinstance(k, yaml.ScalarNode):
            raise DescriptionError(f"{what}: keys must be plain names", path, k.start_mark.line + 1)
        if k.value in out:
            raise DescriptionError(f"{what}: key {excerpt(k.value)!r} appears twice", path, k.start_mark.line + 1)
        out[k.value] = v
    return out


def _plain(node: yaml.Node) -> object:
    return yaml.SafeLoader("").construct_document(node)


def _unknown_keys(m: dict[str, yaml.Node], allowed: set[str], path: Path, what: str) -> None:
    for k, v in m.items():
        if k not in allowed:
            raise DescriptionError(
                f"{what}: unknown key {excerpt(k)!r}; expected one of {', '.join(sorted(allowed))}", path,
                v.start_mark.line + 1,
            )


def _str_map(node: yaml.Node | None, path: Path, what: str) -> dict[str, object]:
    if node is None:
        return {}
    value = _plain(node)
    if not isinstance(value, dict):
        raise DescriptionError(f"{what} must be a mapping", path, node.start_mark.line + 1)
    return {str(k): v for k, v in value.items()}


def load_task(path: str | Path) -> Task:
    """Read a task description (YAML)."""
    return parse_task(read_bytes(path), path)


@dataclass
class _Flat:
    """The task being flattened: its steps so far, with the loops and branches over them."""

    path: Path
    steps: list[Step] = field(default_factory=list)
    loops: list[Loop] = field(default_factory=list)
    branches: list[Branch] = field(default_factory=list)
    names: set[str] = field(default_factory=set)
    repeat: int = 1


def parse_task(data: bytes, source: str | Path) -> Task:
    """Read a task description from YAML text; ``source`` names it in messages and in ``Task.file``."""
    p = Path(source)
    top = _mapping(parse_yaml_bytes(data, p), p, "task")
    _unknown_keys(top, {"task", "description", "repeat", "steps"}, p, "task")
    if "task" not in top or "steps" not in top:
        raise DescriptionError("a task needs 'task' (its name) and 'steps'", p, 1)
    repeat = _plain(top["repeat"]) if "repeat" in top else 1
    if not isinstance(repeat, int) or isinstance(repeat, bool) or not 1 <= repeat <= 1000:
        raise DescriptionError(f"repeat must be a whole number from 1 to 1000; found {excerpt(repr(repeat))}", p,
                               top["repeat"].start_mark.line + 1)
    steps_node = top["steps"]
    if not isinstance(steps_node, yaml.SequenceNode) or not steps_node.value:
        raise DescriptionError("steps must be a non-empty list", p, steps_node.start_mark.line + 1)
    if len(steps_node.value) * repeat > Task.MAX_STEPS:
        raise DescriptionError(f"{len(steps_node.value)} steps repeated {repeat} times make "
                               f"{len(steps_node.value) * repeat}; at most {Task.MAX_STEPS} are accepted",
                               p, steps_node.start_mark.line + 1)
    flat = _Flat(p, repeat=repeat)
    _items(flat, steps_node.value)
    if len(flat.steps) * repeat > Task.MAX_STEPS:
        raise DescriptionError(f"the task makes {len(flat.steps) * repeat} steps; at most {Task.MAX_STEPS} are "
                               "accepted", p, steps_node.start_mark.line + 1)
    description = _plain(top["description"]) if "description" in top else ""
    task = Task.repeated(str(_plain(top["task"])), flat.steps, str(p), str(description or ""), repeat)
    return dataclasses.replace(task, loops=outermost_first(flat.loops), branches=tuple(flat.branches))


def _items(flat: _Flat, nodes: list[yaml.Node]) -> None:
    """Flatten a list of steps and loops (a task's, a loop's body or a branch's) onto ``flat``."""
    for node in nodes:
        m = _mapping(node, flat.path, "step")
        if "loop" not in m:
            _step_and_branches(flat, node, m)
        elif flat.repeat != 1:
            raise DescriptionError("a task with a loop cannot also repeat; put its steps in the loop", flat.path,
                                   node.start_mark.line + 1)
        else:
            _loop(flat, m)
        if len(flat.steps) > Task.MAX_STEPS:
            raise DescriptionError(f"the task makes more than {Task.MAX_STEPS} steps; at most {Task.MAX_STEPS} are "
                                   "accepted", flat.path, node.start_mark.line + 1)


def _step_and_branches(flat: _Flat, node: yaml.Node, m: dict[str, yaml.Node]) -> None:
    """One step, then the steps of each of its branches (``on: {OUTCOME: [...]}``) in the order written."""
    step = _step(node, m, flat.path, flat.names, len(flat.steps) + 1)
    flat.steps.append(step)
    on = m.get("on")
    if on is None:
        return
    if flat.repeat != 1:
        raise DescriptionError("a task with a branch cannot also repeat; put its steps in a loop", flat.path,
                               on.start_mark.line + 1)
    if not isinstance(on, yaml.MappingNode) or not on.value:
        raise DescriptionError("on maps outcomes to the steps that run when the step ends with them, e.g. "
                               "on: {NoPartFound: [...]}", flat.path, on.start_mark.line + 1)
    _mapping(on, flat.path, "on")  # keys plain and once each
    for key, body in on.value:
        line = key.start_mark.line + 1
        if not _OUTCOME.fullmatch(str(key.value)):
            raise DescriptionError(f"on names outcomes such as NoPartFound (or a library's by its IRI); found "
                                   f"{excerpt(repr(key.value))}",
                                   flat.path, line)
        if not isinstance(body, yaml.SequenceNode) or not body.value:
            raise DescriptionError(f"branch {excerpt(key.value)} needs its steps, a non-empty list", flat.path, line)
        first = len(flat.steps) + 1
        _items(flat, body.value)
        flat.branches.append(Branch(step.index, concept_iri(str(key.value)), first, len(flat.steps), line))


def _step(node: yaml.Node, m: dict[str, yaml.Node], p: Path, names: set[str], index: int) -> Step:
    """One step of a task file."""
    line = node.start_mark.line + 1
    _unknown_keys(m, {"name", "command", "bind", "params", "on"}, p, "step")
    if "command" not in m or not isinstance(_plain(m["command"]), str):
        raise DescriptionError("a step needs 'command': the name of a process command (or 'loop')", p, line)
    bind = {k: str(v) for k, v in _str_map(m.get("bind"), p, "bind").items()}
    params = m.get("params")
    lines = {}
    if isinstance(params, yaml.MappingNode):
        lines = {str(k.value): k.start_mark.line + 1 for k, _ in params.value}
    values = {n: _link(v, p, lines.get(n, line)) for n, v in _str_map(params, p, "params").items()}
    name = _step_name(m.get("name"), names, p)
    return Step(index, str(_plain(m["command"])), bind, values, line, lines, name)


def _outcome(m: dict[str, yaml.Node], key: str, p: Path) -> str | None:
    """A loop's ``until``/``while`` outcome (its IRI), if given."""
    if key not in m:
        return None
    value = _plain(m[key])
    if not isinstance(value, str) or not _OUTCOME.fullmatch(value):
        raise DescriptionError(f"{key} names an outcome such as BinEmpty (or a library's by its IRI); found "
                               f"{excerpt(repr(value))}", p,
                               m[key].start_mark.line + 1)
    return concept_iri(value)


def _loop(flat: _Flat, item: dict[str, yaml.Node]) -> None:
    """A ``loop:`` item: its body goes onto ``flat`` twice (the first iteration, then the ones after it)."""
    p = flat.path
    _unknown_keys(item, {"loop"}, p, "step")
    node = item["loop"]
    line = node.start_mark.line + 1
    m = _mapping(node, p, "loop")
    _unknown_keys(m, {"until", "while", "max", "steps"}, p, "loop")
    until, goes_on = _outcome(m, "until", p), _outcome(m, "while", p)
    most = _plain(m["max"]) if "max" in m else None
    if most is not None and (not isinstance(most, int) or isinstance(most, bool) or not 1 <= most <= 1_000_000):
        raise DescriptionError(f"max must be a whole number from 1 to 1000000; found {excerpt(repr(most))}", p,
                               m["max"].start_mark.line + 1)
    if until is None and goes_on is None and most is None:
        raise DescriptionError("a loop needs a way out: 'until: OUTCOME', 'max: N' or both (or 'while: OUTCOME')", p,
                               line)
    body = m.get("steps")
    if not isinstance(body, yaml.SequenceNode) or not body.value:
        raise DescriptionError("a loop needs 'steps', a non-empty list", p, line)
    entry, known, inner = len(flat.steps) + 1, len(flat.branches), len(flat.loops)
    _items(flat, body.value)
    first = len(flat.steps) + 1
    n = first - entry
    if len(flat.steps) + n > Task.MAX_STEPS:
        raise DescriptionError(f"the task makes more than {Task.MAX_STEPS} steps; at most {Task.MAX_STEPS} are "
                               "accepted", p, line)
    flat.steps += [dataclasses.replace(s, index=s.index + n) for s in flat.steps[entry - 1:]]
    flat.branches += [dataclasses.replace(b, step=b.step + n, first=b.first + n, last=b.last + n)
                      for b in flat.branches[known:]]
    # a loop inside the body appears in each copy of it, with positions of its own
    flat.loops += [dataclasses.replace(lp, entry=lp.entry + n, first=lp.first + n, last=lp.last + n)
                   for lp in flat.loops[inner:]]
    flat.loops.append(Loop(entry, first, len(flat.steps), until, most, line, goes_on))


def _step_name(node: yaml.Node | None, seen: set[str], path: Path) -> str | None:
    """A step's ``name:``: a plain name, unique in the task."""
    if node is None:
        return None
    name = _plain(node)
    line = node.start_mark.line + 1
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise DescriptionError(f"a step name must be a plain name such as localize; found {excerpt(repr(name))}",
                               path, line)
    if name in seen:
        raise DescriptionError(f"step name {name!r} appears twice; each step needs its own name", path, line)
    seen.add(name)
    return name


def _link(value: object, path: Path, line: int) -> object:
    """A parameter value, or the earlier step's output it takes (``{from: STEP, output: NAME}``)."""
    if not isinstance(value, dict):
        return value
    if not {"from", "output"} <= set(value) <= {"from", "output", "offset"} or \
            not all(isinstance(value[k], str) for k in ("from", "output")):
        raise DescriptionError("a parameter taken from an earlier step reads {from: STEP, output: NAME} (with "
                               f"offset: [x, y, z, rx, ry, rz] for a pose); found {excerpt(repr(value))}", path, line)
    return Link(str(value["from"]), str(value["output"]), _offset(value.get("offset"), path, line))


OFFSET_SIZE = 6
"""An offset is added to a pose: x, y, z (m), rx, ry, rz (deg)."""


def _offset(value: object, path: Path, line: int) -> tuple[float, ...] | None:
    """A link's offset: six finite numbers, or None if it has none."""
    if value is None:
        return None
    numbers: list[float] = []
    if isinstance(value, list) and len(value) == OFFSET_SIZE:
        for v in value:
            try:
                numbers.append(float(v) if isinstance(v, int | float) and not isinstance(v, bool) else math.nan)
            except OverflowError:  # a whole number too large for any pose
                numbers.append(math.inf)
    if len(numbers) != OFFSET_SIZE or not all(math.isfinite(v) for v in numbers):
        raise DescriptionError(f"an offset is a pose's change [x, y, z, rx, ry, rz] (metres, degrees): six finite "
                               f"numbers; found {excerpt(repr(value))}", path, line)
    return tuple(numbers)


def _step_entry(task: Task, s: Step) -> dict[str, object]:
    entry: dict[str, object] = {"name": s.name} if s.name else {}
    entry["command"] = s.command
    if s.bind:
        entry["bind"] = dict(s.bind)
    if s.params:
        entry["params"] = {n: plain_value(v) for n, v in s.params.items()}
    branches = task.branches_of(s.index) if task.branches else ()
    if branches:
        entry["on"] = {concept_value(b.outcome): _entries(task, b.first, b.last) for b in branches}
    return entry


def _loop_entry(task: Task, loop: Loop) -> dict[str, object]:
    out: dict[str, object] = {}
    if loop.until:
        out["until"] = concept_value(loop.until)
    if loop.while_outcome:
        out["while"] = concept_value(loop.while_outcome)
    if loop.max is not None:
        out["max"] = loop.max
    out["steps"] = _entries(task, loop.entry, loop.first - 1)
    return out


def _entries(task: Task, start: int, end: int) -> list[dict[str, object]]:
    """The file's items for step positions ``start`` to ``end``: steps with their branches, and loops
    (with the loops inside their bodies)."""
    out: list[dict[str, object]] = []
    i = start
    while i <= end:
        loop = task.loop_starting(i, end) if task.loops else None
        if loop is not None:
            out.append({"loop": _loop_entry(task, loop)})
            i = loop.last + 1
            continue
        out.append(_step_entry(task, task.steps[i - 1]))
        i = max([i, *(b.last for b in task.branches_of(i))]) + 1 if task.branches else i + 1
    return out


def task_entries(task: Task) -> list[dict[str, object]]:
    """The task's items as the task file writes them (one round): steps with their ``on``, and loops."""
    return _entries(task, 1, len(task.one_round()))


def task_to_yaml(task: Task, block: bool = False) -> str:
    """Write a task as a task file (one round of its steps when it repeats): the one task writer.

    ``block`` puts every value on a line of its own, so that a finding's line names its field.
    """
    doc: dict[str, object] = {"task": task.name}
    if task.description:
        doc["description"] = task.description
    if task.repeat != 1:
        doc["repeat"] = task.repeat
    entries = task_entries(task)
    items = _step_texts(entries, block) if entries else None
    if items is None:
        return _dump({**doc, "steps": entries}, block)
    return _dump(doc, block) + "steps:\n" + "".join(items)


ITEMS_KEPT = 100_000
"""Most step items whose text :func:`_step_texts` keeps (a long task's repairs repeat almost all its steps)."""

_ITEM_TEXT: dict[tuple[bool, str], str] = {}


def _dump(doc: object, block: bool) -> str:
    return yaml.dump(doc, Dumper=PlainDumper if block else TaskDumper, sort_keys=False, default_flow_style=False,
                     allow_unicode=True)


def _step_texts(entries: list[dict[str, object]], block: bool) -> list[str] | None:
    """The text of each item of the ``steps`` list, each item written once per process: an item of a block list
    is written alike wherever it stands, so the list's text is its items' texts one after another. Items not
    written before are written together and split where each starts (``- `` at the line's start; their other
    lines are indented); None when the split does not give one text per item (then the whole is written)."""
    keys = [(block, repr(e)) for e in entries]
    new = {k: e for k, e in zip(keys, entries, strict=True) if k not in _ITEM_TEXT}
    if new:
        text = _dump({"steps": list(new.values())}, block).removeprefix("steps:\n")
        starts = [m.start() for m in re.finditer(r"^- ", text, re.MULTILINE)]
        if len(starts) != len(new) or starts[0] != 0:
            return None
        if len(_ITEM_TEXT) + len(new) > ITEMS_KEPT:
            _ITEM_TEXT.clear()
        _ITEM_TEXT.update(zip(new, (text[a:b] for a, b in zip(starts, [*starts[1:], len(text)], strict=True)),
                              strict=True))
    return [_ITEM_TEXT[k] for k in keys]


class TaskDumper(PlainDumper):
    """One style for every step: mappings in block style, a list in flow style only when it holds plain
    values alone (a pose, ``[0.4, 0.1, 0.2, 0, 180, 0]``)."""


def _block_mapping(dumper: yaml.SafeDumper, data: dict[Any, Any]) -> yaml.Node:
    return dumper.represent_mapping("tag:yaml.org,2002:map", data, flow_style=False)


def _sequence(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    plain = all(not isinstance(v, (dict, list)) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=plain)


TaskDumper.add_representer(dict, _block_mapping)
TaskDumper.add_representer(list, _sequence)
