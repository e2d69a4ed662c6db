"""Feasibility of many cell configurations against all processes and given tasks (batch.lp).

No search is needed, so many configurations are grounded together in one ``Control``
(a chunk), and chunks run on a pool of worker processes. Configurations are sets of
catalogue devices: equal sets are reasoned about once. For a task that is not plausible,
stage 1 finds the catalogue devices that fill every missing role; stage 2 checks the
configuration plus each of them and keeps the cheapest that makes the task plausible
("none" when one device is not enough).
"""

from __future__ import annotations

import csv
import json
import random
from collections import Counter, defaultdict
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from plugnproduce.description.model import DeviceDescription, ProcessDescription, Task
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning import schema as s
from plugnproduce.reasoning import solver
from plugnproduce.reasoning.facts import config_facts, fact_book, task_facts
from plugnproduce.reasoning.terms import Atom, program

CHUNK = 400
"""Configurations grounded together in one Control."""


@dataclass(frozen=True)
class Configuration:
    """A candidate cell: a name and the catalogue devices plugged in."""

    name: str
    devices: tuple[str, ...]


@dataclass(frozen=True)
class BatchRow:
    """The answer for one configuration."""

    config: str
    devices: tuple[str, ...]
    offered: tuple[str, ...]
    plausible: tuple[str, ...]
    cheapest: dict[str, str | None] = field(default_factory=dict)
    """Each task that is not plausible → the cheapest catalogue device whose addition makes it plausible."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"config": self.config, "devices": list(self.devices), "offered": list(self.offered),
                "plausible": list(self.plausible), "cheapest_device": dict(self.cheapest)}

    def to_csv(self) -> list[str]:
        """A CSV row (see :data:`CSV_HEADER`); lists are space separated."""
        cheapest = " ".join(f"{t}={d or '-'}" for t, d in self.cheapest.items())
        return [self.config, " ".join(self.devices), " ".join(self.offered), " ".join(self.plausible), cheapest]


CSV_HEADER = ["config", "devices", "offered", "plausible", "cheapest_device"]


# ------------------------------------------------------------------ configurations in


def generate(catalogue: Sequence[DeviceDescription], count: int, sizes: tuple[int, int],
             seed: int) -> list[Configuration]:
    """``count`` random configurations of ``sizes[0]`` to ``sizes[1]`` distinct catalogue devices."""
    ids = sorted(d.id for d in catalogue)
    low, high = max(0, sizes[0]), min(len(ids), sizes[1])
    if low > high:
        raise ValueError(f"sizes {sizes[0]}-{sizes[1]} do not fit a catalogue of {len(ids)} devices")
    rng = random.Random(seed)
    width = len(str(count))
    return [Configuration(f"g{n:0{width}d}", tuple(sorted(rng.sample(ids, rng.randint(low, high)))))
            for n in range(1, count + 1)]


def read_configurations(path: str | Path) -> list[Configuration]:
    """Configurations from JSONL (``{"config": name, "devices": [ids]}`` a line) or CSV (config, devices)."""
    p = Path(path)
    text = p.read_text(encoding="utf-8")
    if p.suffix.lower() == ".csv":
        rows = list(csv.reader(text.splitlines()))
        start = 1 if rows and rows[0] and rows[0][0].strip().lower() == "config" else 0
        return [_config(p, n + 1, r[0], (r[1] if len(r) > 1 else "").replace(";", " ").split())
                for n, r in enumerate(rows[start:], start=start) if r]
    out = []
    for n, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        try:
            doc = json.loads(line)
        except json.JSONDecodeError as exc:
            raise DescriptionError(f"not a JSON object: {exc.msg}", p, n) from exc
        if not isinstance(doc, dict) or not isinstance(doc.get("devices"), list):
            raise DescriptionError('expected {"config": NAME, "devices": [DEVICE-ID, ...]}', p, n)
        out.append(_config(p, n, str(doc.get("config", f"c{n}")), [str(d) for d in doc["devices"]]))
    return out


def _config(path: Path, line: int, name: str, devices: list[str]) -> Configuration:
    if len(set(devices)) != len(devices):
        raise DescriptionError(f"configuration {name!r} lists a device twice", path, line)
    return Configuration(name, tuple(devices))


# ------------------------------------------------------------------ the work of one chunk (in a worker)

_STATIC = ""
_TASKS: tuple[str, ...] = ()


def _init(static: str, tasks: tuple[str, ...]) -> None:
    global _STATIC, _TASKS
    _STATIC, _TASKS = static, tasks


def _checks(names: Iterable[str]) -> list[Atom]:
    return [s.Check(c, t) for c in names for t in _TASKS]


Chunk = list[tuple[str, tuple[str, ...]]]
"""Configurations (key, device ids) grounded together."""
Answer = tuple[str, list[str], list[str], dict[str, str | None]]
"""Key, offered processes, plausible tasks, cheapest device per task that is not plausible."""


def run_chunk(chunk: Chunk) -> list[Answer]:
    """Offered processes, plausible tasks and cheapest additions for a chunk of (name, devices)."""
    facts: list[Atom] = []
    for name, devices in chunk:
        facts += config_facts(name, devices)
    model = solver.solve(solver.BATCH, _STATIC + program(facts + _checks(n for n, _ in chunk)))
    offered: dict[str, list[str]] = defaultdict(list)
    for o in model[s.Offered]:
        offered[o.c].append(o.p)
    plausible: dict[str, list[str]] = defaultdict(list)
    for p in model[s.Plausible]:
        plausible[p.c].append(p.t)
    cheapest = _stage2(dict(chunk), model[s.Addable]) if _TASKS else {}
    out = []
    for name, _ in chunk:
        missing = {t: cheapest.get((name, t)) for t in _TASKS if t not in plausible[name]}
        out.append((name, sorted(offered[name]), sorted(plausible[name], key=_TASKS.index), missing))
    return out


def _stage2(devices: dict[str, tuple[str, ...]], addable: list[s.Addable]) -> dict[tuple[str, str], str]:
    if not addable:
        return {}
    facts: list[Atom] = []
    for n, a in enumerate(addable):
        v = f"v{n}"
        facts += config_facts(v, (*devices[a.c], a.a))
        facts += [s.Variant(v, a.c, a.a), s.Check(v, a.t)]
    model = solver.solve(solver.CHEAPEST, _STATIC + program(facts))
    best: dict[tuple[str, str], str] = {}
    for c in sorted(model[s.Cheapest], key=lambda x: x.a, reverse=True):
        best[(c.c, c.t)] = c.a  # ties: the first id wins
    return best


# ------------------------------------------------------------------ the batch


def static_program(catalogue: Sequence[DeviceDescription], tasks: Sequence[tuple[str, Task]], taxonomy: Taxonomy,
                   processes: Sequence[ProcessDescription]) -> str:
    """Facts shared by every configuration: processes, catalogue devices, tasks."""
    book = fact_book(taxonomy, processes)
    return (book.process_text() + book.devices_text(catalogue)
            + program(a for name, t in tasks for a in task_facts(t, name)))


def task_names(tasks: Sequence[Task]) -> list[tuple[str, Task]]:
    """Tasks by a name unique in the batch (their own, suffixed when two share one)."""
    seen: dict[str, int] = defaultdict(int)
    out = []
    for t in tasks:
        seen[t.name] += 1
        out.append((t.name if seen[t.name] == 1 else f"{t.name}-{seen[t.name]}", t))
    return out


def batch(
    configurations: Sequence[Configuration],
    catalogue: Sequence[DeviceDescription],
    tasks: Sequence[Task],
    taxonomy: Taxonomy,
    processes: Sequence[ProcessDescription],
    workers: int = 2,
    chunk: int = CHUNK,
    progress: Callable[[int], None] | None = None,
) -> Iterator[BatchRow]:
    """One :class:`BatchRow` per configuration, in order; ``progress(n)`` is told as configurations finish."""
    known = {d.id for d in catalogue}
    for c in configurations:
        unknown = sorted(set(c.devices) - known)
        if unknown:
            raise KeyError(f"device {unknown[0]!r} (configuration {c.name!r}); not in the catalogue")
    named = task_names(tasks)
    static = static_program(catalogue, named, taxonomy, processes)
    names = tuple(n for n, _ in named)
    weight = Counter(frozenset(c.devices) for c in configurations)
    unique = sorted(weight, key=sorted)
    keys = {u: f"u{n}" for n, u in enumerate(unique)}
    sets = {k: u for u, k in keys.items()}
    jobs = [[(keys[u], tuple(sorted(u))) for u in unique[i:i + chunk]] for i in range(0, len(unique), chunk)]
    results: dict[str, tuple[list[str], list[str], dict[str, str | None]]] = {}
    for part in _map(jobs, static, names, workers):
        for key, offered, plausible, cheapest in part:
            results[key] = (offered, plausible, cheapest)
        if progress is not None:
            progress(sum(weight[sets[key]] for key, *_ in part))
    for c in configurations:
        offered, plausible, cheapest = results[keys[frozenset(c.devices)]]
        yield BatchRow(c.name, c.devices, tuple(offered), tuple(plausible), cheapest)


def _map(jobs: list[Chunk], static: str, names: tuple[str, ...], workers: int) -> Iterator[list[Answer]]:
    if workers <= 1 or len(jobs) <= 1:
        _init(static, names)
        yield from (run_chunk(j) for j in jobs)
        return
    with ProcessPoolExecutor(workers, initializer=_init, initargs=(static, names)) as pool:
        yield from pool.map(run_chunk, jobs)
