"""Feasibility of many cell configurations: offered processes, plausible tasks, cheapest purchases.

What depends on one device is reasoned once (:mod:`.abilities`); each configuration only
combines those answers (:mod:`.feasibility`, :mod:`.purchases`). Configurations stream in and
rows stream out in input order: chunks of configurations go to worker processes (or a Dask
cluster, :mod:`.cluster`) with a bounded number in flight, so memory does not grow with the
number of configurations.
"""

from __future__ import annotations

import csv
import itertools
import json
import random
from collections import defaultdict, deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

from plugnproduce.description.model import DeviceDescription, ProcessDescription, Task
from plugnproduce.errors import DescriptionError
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.reasoning.abilities import Abilities, abilities
from plugnproduce.reasoning.feasibility import Feasibility
from plugnproduce.reasoning.purchases import Purchase, purchase

CHUNK = 2_000
"""Configurations sent to a worker at a time."""
MAX_LINE = 1 << 20
"""Longest configuration line read (bytes)."""


@dataclass(frozen=True)
class Configuration:
    """A candidate cell: a name and the catalogue devices plugged in (and where it was read)."""

    name: str
    devices: tuple[str, ...]
    file: str | None = field(default=None, compare=False)
    line: int | None = field(default=None, compare=False)


@dataclass(frozen=True)
class BatchRow:
    """The answer for one configuration."""

    config: str
    devices: tuple[str, ...]
    offered: tuple[str, ...]
    plausible: tuple[str, ...]
    purchase: Purchase | None = None
    """The cheapest sets of devices to add so every task is plausible; None when they all are."""

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"config": self.config, "devices": list(self.devices), "offered": list(self.offered),
                "plausible": list(self.plausible),
                "purchase": self.purchase.to_json() if self.purchase is not None else None}

    def to_csv(self) -> list[str]:
        """A CSV row (see :data:`CSV_HEADER`); lists are space separated."""
        bought = self.purchase.text() if self.purchase is not None else ""
        return [self.config, " ".join(self.devices), " ".join(self.offered), " ".join(self.plausible), bought]


CSV_HEADER = ["config", "devices", "offered", "plausible", "purchase"]


# ------------------------------------------------------------------ configurations in


def generate(catalogue: Sequence[DeviceDescription], count: int, sizes: tuple[int, int],
             seed: int) -> Iterator[Configuration]:
    """``count`` random configurations of ``sizes[0]`` to ``sizes[1]`` distinct catalogue devices, lazily."""
    ids = sorted(d.id for d in catalogue)
    low, high = max(0, sizes[0]), min(len(ids), sizes[1])
    if low > high:
        raise ValueError(f"sizes {sizes[0]}-{sizes[1]} do not fit a catalogue of {len(ids)} devices")
    return _generated(ids, count, low, high, seed)


def _generated(ids: list[str], count: int, low: int, high: int, seed: int) -> Iterator[Configuration]:
    rng = random.Random(seed)
    width = len(str(count))
    for n in range(1, count + 1):
        yield Configuration(f"g{n:0{width}d}", tuple(sorted(rng.sample(ids, rng.randint(low, high)))))


def read_configurations(path: str | Path) -> Iterator[Configuration]:
    """Configurations read one line at a time from JSONL (``{"config": name, "devices": [ids]}``) or CSV."""
    p = Path(path)
    return _csv(p) if p.suffix.lower() == ".csv" else _jsonl_file(p)


def _jsonl_file(path: Path) -> Iterator[Configuration]:
    with path.open(encoding="utf-8") as f:
        yield from configurations_from(bounded_lines(f), str(path))


def bounded_lines(stream: TextIO) -> Iterator[str]:
    """The lines of a text stream, none read past :data:`MAX_LINE` characters (a longer one is cut there)."""
    return iter(lambda: stream.readline(MAX_LINE + 1), "")


def configurations_from(lines: Iterable[str], source: str) -> Iterator[Configuration]:
    """Configurations from JSONL lines (a file, standard input); ``source`` names them in messages."""
    for n, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        if len(line) > MAX_LINE:
            raise DescriptionError(f"line longer than {MAX_LINE} characters", source, n)
        try:
            doc = json.loads(line)
        except (json.JSONDecodeError, RecursionError) as exc:
            raise DescriptionError(f"not a JSON object: {getattr(exc, 'msg', 'nested too deep')}", source, n) from exc
        if (not isinstance(doc, dict) or not isinstance(doc.get("devices"), list)
                or not all(isinstance(d, str) for d in doc["devices"])):
            raise DescriptionError('expected {"config": NAME, "devices": [DEVICE-ID, ...]}', source, n)
        yield _config(source, n, str(doc.get("config", f"c{n}")), doc["devices"])


def _csv(path: Path) -> Iterator[Configuration]:
    with path.open(encoding="utf-8", newline="") as f:
        reader = csv.reader(f)
        try:
            for row in reader:
                n = reader.line_num
                if not row or (n == 1 and row[0].strip().lower() == "config"):
                    continue
                yield _config(str(path), n, row[0], (row[1] if len(row) > 1 else "").replace(";", " ").split())
        except csv.Error as exc:
            raise DescriptionError(f"not a CSV row: {exc}", path, reader.line_num) from exc


def _config(source: str, line: int, name: str, devices: list[str]) -> Configuration:
    if len(set(devices)) != len(devices):
        raise DescriptionError(f"configuration {name!r} lists a device twice", source, line)
    return Configuration(name, tuple(devices), source, line)


# ------------------------------------------------------------------ the work of one chunk (in a worker)


class Engine:
    """Answers configurations from the per-device :class:`Abilities`; purchases are remembered like findings."""

    def __init__(self, abilities: Abilities, top: int = 1) -> None:
        self.feasibility = Feasibility(abilities)
        self.top = top
        self._bits = {d: 1 << n for n, d in enumerate(abilities.devices)}
        relevant = 0
        for r in self.feasibility.relevant:
            relevant |= r
        self._relevant = relevant
        self._bought: dict[int, Purchase | None] = {}

    def mask(self, config: Configuration) -> int:
        """The configuration as a bit mask; an unknown device is bad input."""
        out = 0
        for d in config.devices:
            bit = self._bits.get(d)
            if bit is None:
                raise DescriptionError(f"device {d!r} of configuration {config.name!r} is not in the catalogue",
                                       config.file, config.line)
            out |= bit
        return out

    def row(self, config: Configuration) -> BatchRow:
        """The answer for one configuration."""
        mask = self.mask(config)
        f = self.feasibility
        return BatchRow(config.name, config.devices, f.offered(mask), f.plausible(mask), self._purchase(mask))

    def _purchase(self, mask: int) -> Purchase | None:
        key = mask & self._relevant
        if key not in self._bought:
            if len(self._bought) >= 1 << 16:
                self._bought.clear()
            self._bought[key] = purchase(self.feasibility, mask, self.top)
        return self._bought[key]


_ENGINE: Engine | None = None


def _start(engine: Engine) -> None:
    global _ENGINE
    _ENGINE = engine


def run_chunk(chunk: list[Configuration], engine: Engine | None = None) -> list[BatchRow]:
    """The rows of a chunk of configurations (in a worker, the engine its start-up was given)."""
    e = engine or _ENGINE
    if e is None:
        raise RuntimeError("run_chunk needs an engine")
    return [e.row(c) for c in chunk]


# ------------------------------------------------------------------ the batch


def task_names(tasks: Sequence[Task]) -> list[tuple[str, Task]]:
    """Tasks by a name unique in the batch (their own, suffixed when two share one)."""
    seen: dict[str, int] = defaultdict(int)
    out = []
    for t in tasks:
        seen[t.name] += 1
        out.append((t.name if seen[t.name] == 1 else f"{t.name}-{seen[t.name]}", t))
    return out


def engine(catalogue: Sequence[DeviceDescription], tasks: Sequence[Task], taxonomy: Taxonomy,
           processes: Sequence[ProcessDescription], top: int = 1) -> Engine:
    """Reason once over the catalogue and tasks; the engine then answers any configuration of them."""
    return Engine(abilities(catalogue, task_names(tasks), taxonomy, processes), top)


Mapper = Callable[[Engine, Iterator[list[Configuration]]], Iterator[list[BatchRow]]]
"""Runs chunks somewhere (here, a process pool, a Dask cluster) and yields their rows in chunk order."""


def batch(
    configurations: Iterable[Configuration],
    catalogue: Sequence[DeviceDescription],
    tasks: Sequence[Task],
    taxonomy: Taxonomy,
    processes: Sequence[ProcessDescription],
    workers: int = 2,
    chunk: int = CHUNK,
    progress: Callable[[int], None] | None = None,
    top: int = 1,
    mapper: Mapper | None = None,
) -> Iterator[BatchRow]:
    """One :class:`BatchRow` per configuration, in order; ``progress(n)`` is told as configurations finish."""
    e = engine(catalogue, tasks, taxonomy, processes, top)
    chunks = _chunks(configurations, chunk)
    run = mapper or (lambda eng, cs: _pool(eng, cs, workers))
    for rows in run(e, chunks):
        yield from rows
        if progress is not None:
            progress(len(rows))


def _chunks(configurations: Iterable[Configuration], size: int) -> Iterator[list[Configuration]]:
    it = iter(configurations)
    while part := list(itertools.islice(it, size)):
        yield part


def _pool(e: Engine, chunks: Iterator[list[Configuration]], workers: int) -> Iterator[list[BatchRow]]:
    if workers <= 1:
        yield from (run_chunk(c, e) for c in chunks)
        return
    with ProcessPoolExecutor(workers, initializer=_start, initargs=(e,)) as pool:
        pending: deque[Future[list[BatchRow]]] = deque()
        for c in chunks:
            pending.append(pool.submit(run_chunk, c))
            if len(pending) >= 2 * workers:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
