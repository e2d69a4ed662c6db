"""Feasibility of many cell configurations: offered processes, plausible tasks, cheapest purchases.

What depends on one device is reasoned once (:mod:`plugnproduce.reasoning.checks.abilities`); each configuration only
combines those answers (:mod:`.feasibility`, :mod:`.purchases`). Configurations stream in and
rows stream out in input order: chunks of configurations go to worker processes (or a Dask
cluster, :mod:`.cluster`) with a bounded number in flight, so memory does not grow with the
number of configurations.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import random
from collections import defaultdict, deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TextIO, cast

from plugnproduce.batch.feasibility import MEMORY, Feasibility, Key
from plugnproduce.batch.purchases import Purchase, purchase
from plugnproduce.description.model import DeviceDescription, Task
from plugnproduce.errors import DescriptionError
from plugnproduce.reasoning.checks.abilities import Abilities, abilities

if TYPE_CHECKING:
    from plugnproduce.knowledge import Knowledge

CHUNK = 2_000
"""Configurations sent to a worker at a time."""
SOLO = 100_000
"""Configurations answered in the batch's own process before worker processes start: about two seconds of
work, below which starting workers and sending them the reasoned catalogue and the chunks costs more CPU (and on
a busy machine more time) than they save."""
MAX_LINE = 1 << 20
"""Longest configuration line read (bytes)."""


@dataclass(frozen=True)
class Configuration:
    """A candidate cell: a name and the catalogue devices plugged in (and where it was read)."""

    name: str
    devices: tuple[str, ...]
    file: str | None = field(default=None, compare=False)
    line: int | None = field(default=None, compare=False)

    def __reduce__(self) -> tuple[type[Configuration], tuple[str, tuple[str, ...], str | None, int | None]]:
        """Pickled as its fields (half the time of a dataclass's default): chunks go to workers by pickle."""
        return Configuration, (self.name, self.devices, self.file, self.line)


@dataclass(frozen=True)
class BatchRow:
    """The answer for one configuration."""

    config: str
    devices: tuple[str, ...]
    offered: tuple[str, ...]
    plausible: tuple[str, ...]
    purchase: Purchase | None = None
    """The cheapest sets of devices to add so every task is plausible; None when they all are."""

    @property
    def outcome(self) -> str:
        """One of :data:`OUTCOMES`: every task plausible, a purchase helps, a role to bind, or nothing helps."""
        return "plausible" if self.purchase is None else self.purchase.outcome

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
OUTCOMES = ("plausible", "buy", "ambiguous", "impossible")
"""What a configuration's answer comes to (:attr:`BatchRow.outcome`), in the order a batch's tally tells them."""
Tally = dict[str, int]
Known = tuple[tuple[str, ...], Purchase | None, str, str]
"""A configuration's plausible tasks, its purchase, the end of its JSON line from "plausible" on, its outcome."""
_json_text: Callable[[str], str] = json.encoder.encode_basestring_ascii
"""``json.dumps`` of a string (the C function it calls)."""


# ------------------------------------------------------------------ configurations in


def generate(catalogue: Sequence[DeviceDescription] | Sequence[str], count: int, sizes: tuple[int, int],
             seed: int) -> Iterator[Configuration]:
    """``count`` random configurations of ``sizes[0]`` to ``sizes[1]`` distinct catalogue devices (descriptions
    or ids), lazily."""
    ids = sorted(d if isinstance(d, str) else d.id for d in catalogue)
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
        self._bits = abilities.bits
        self._tasks = range(len(abilities.tasks))
        self._names = tuple(t.name for t in abilities.tasks)
        self._known: dict[Key, Known] = {}
        self._offered: dict[int, tuple[tuple[str, ...], str]] = {}

    @property
    def devices(self) -> tuple[str, ...]:
        """The catalogue's device ids, sorted."""
        return self.feasibility.abilities.devices

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
        plausible, bought, _, _ = self._answer(mask)
        return BatchRow(config.name, config.devices, self._offer(mask)[0], plausible, bought)

    def _answer(self, mask: int) -> Known:
        """The plausible tasks and the purchase of a configuration, remembered by what they depend on (every
        task's key: see feasibility.py and purchases.py), with their JSON and outcome."""
        key = self.feasibility.key_all(mask)
        known = self._known.get(key)
        if known is None:
            if len(self._known) >= MEMORY:
                self._known.clear()
            f = self.feasibility
            plausible = tuple(self._names[t] for t in self._tasks if not f.findings(t, mask))
            bought = None if len(plausible) == len(self._names) else purchase(f, mask, self.top)
            tail = (f'"plausible": {json.dumps(list(plausible))}, '
                    f'"purchase": {json.dumps(bought.to_json() if bought is not None else None)}}}\n')
            known = self._known[key] = (plausible, bought, tail, "plausible" if bought is None else bought.outcome)
        return known

    def _offer(self, mask: int) -> tuple[tuple[str, ...], str]:
        """The processes a configuration offers and their JSON, remembered by the roles its devices fill."""
        fill = self.feasibility.fill(mask)
        found = self._offered.get(fill)
        if found is None:
            if len(self._offered) >= MEMORY:
                self._offered.clear()
            offered = self.feasibility.offered(mask, fill)
            found = self._offered[fill] = (offered, json.dumps(list(offered)))
        return found

    def line(self, config: Configuration) -> str:
        """The JSONL line of one configuration: ``json.dumps(row.to_json())``, answers' JSON remembered."""
        return self._line(config, self.mask(config))[0]

    def _line(self, config: Configuration, mask: int) -> tuple[str, str]:
        """The JSONL line and the outcome of one configuration."""
        _, _, tail, outcome = self._answer(mask)
        devices = ", ".join(map(_json_text, config.devices))
        return (f'{{"config": {_json_text(config.name)}, "devices": [{devices}], '
                f'"offered": {self._offer(mask)[1]}, {tail}'), outcome

    def text(self, configs: list[Configuration], form: str) -> tuple[str, Tally]:
        """The report of some configurations: JSONL lines, or CSV rows (``form`` "csv"), and how many of them
        come to each of :data:`OUTCOMES`."""
        tally = dict.fromkeys(OUTCOMES, 0)
        if form != "csv":
            lines = []
            for c in configs:
                line, outcome = self._line(c, self.mask(c))
                lines.append(line)
                tally[outcome] += 1
            return "".join(lines), tally
        buf = io.StringIO()
        rows = [self.row(c) for c in configs]
        for r in rows:
            tally[r.outcome] += 1
        csv.writer(buf, lineterminator="\n").writerows(r.to_csv() for r in rows)
        return buf.getvalue(), tally


_ENGINE: Engine | None = None


def _start(engine: Engine) -> None:
    global _ENGINE
    _ENGINE = engine


def run_chunk(chunk: list[Configuration], form: str = "rows",
              engine: Engine | None = None) -> list[BatchRow] | tuple[str, Tally]:
    """Rows for a chunk of configurations, or their report text (``form`` "jsonl" or "csv") with its tally; in
    a worker, with the engine its start-up was given."""
    e = engine or _ENGINE
    if e is None:
        raise RuntimeError("run_chunk needs an engine")
    return [e.row(c) for c in chunk] if form == "rows" else e.text(chunk, form)


# ------------------------------------------------------------------ the batch


def task_names(tasks: Sequence[Task]) -> list[tuple[str, Task]]:
    """Tasks by a name unique in the batch (their own, suffixed when two share one)."""
    seen: dict[str, int] = defaultdict(int)
    out = []
    for t in tasks:
        seen[t.name] += 1
        out.append((t.name if seen[t.name] == 1 else f"{t.name}-{seen[t.name]}", t))
    return out


def engine(catalogue: Sequence[DeviceDescription], tasks: Sequence[Task], knowledge: Knowledge,
           top: int = 1) -> Engine:
    """Reason once over the catalogue and tasks; the engine then answers any configuration of them."""
    return Engine(abilities(catalogue, task_names(tasks), knowledge), top)


Part = list[BatchRow] | tuple[str, Tally]
Mapper = Callable[[Engine, Iterator[list[Configuration]], str], Iterator[Part]]
"""Runs chunks somewhere (here, a process pool, a Dask cluster) in a form ("rows", "jsonl", "csv") and
yields their answers in chunk order."""


def batch(
    configurations: Iterable[Configuration],
    catalogue: Sequence[DeviceDescription],
    tasks: Sequence[Task],
    knowledge: Knowledge,
    workers: int = 2,
    chunk: int = CHUNK,
    progress: Callable[[int], None] | None = None,
    top: int = 1,
    mapper: Mapper | None = None,
    solo: int = SOLO,
) -> Iterator[BatchRow]:
    """One :class:`BatchRow` per configuration, in order; ``progress(n)`` is told as configurations finish.
    The first ``solo`` configurations are answered in this process; ``workers`` processes answer the rest."""
    e = engine(catalogue, tasks, knowledge, top)
    for part, n in _run(e, configurations, "rows", workers, chunk, mapper, solo):
        yield from cast(list[BatchRow], part)
        if progress is not None:
            progress(n)


def report(
    configurations: Iterable[Configuration],
    catalogue: Sequence[DeviceDescription],
    tasks: Sequence[Task],
    knowledge: Knowledge,
    form: str = "jsonl",
    workers: int = 2,
    chunk: int = CHUNK,
    progress: Callable[[int], None] | None = None,
    top: int = 1,
    mapper: Mapper | None = None,
    tally: Tally | None = None,
    solo: int = SOLO,
) -> Iterator[str]:
    """The report of :func:`batch` as text, a chunk at a time: JSONL lines (``BatchRow.to_json``) or CSV rows
    (``form`` "csv", without the header). The text is made where the chunk is answered (in the workers);
    ``tally`` counts the configurations by :data:`OUTCOMES` as their text comes."""
    e = engine(catalogue, tasks, knowledge, top)
    return report_from(e, configurations, form, workers, chunk, progress, mapper, tally, solo)


def report_from(e: Engine, configurations: Iterable[Configuration], form: str = "jsonl", workers: int = 2,
                chunk: int = CHUNK, progress: Callable[[int], None] | None = None, mapper: Mapper | None = None,
                tally: Tally | None = None, solo: int = SOLO) -> Iterator[str]:
    """:func:`report` by an engine already built (:func:`engine`, or one kept from an earlier batch)."""
    for part, n in _run(e, configurations, form, workers, chunk, mapper, solo):
        text, counted = cast(tuple[str, Tally], part)
        yield text
        if tally is not None:
            for k, v in counted.items():
                tally[k] = tally.get(k, 0) + v
        if progress is not None:
            progress(n)


def _run(e: Engine, configurations: Iterable[Configuration], form: str, workers: int, chunk: int,
         mapper: Mapper | None, solo: int = SOLO) -> Iterator[tuple[Part, int]]:
    sizes: deque[int] = deque()

    def chunks() -> Iterator[list[Configuration]]:
        it = iter(configurations)
        while part := list(itertools.islice(it, chunk)):
            sizes.append(len(part))
            yield part

    run = mapper or (lambda eng, cs, f: _pool(eng, cs, f, workers, solo))
    for part in run(e, chunks(), form):
        yield part, sizes.popleft()


def _pool(e: Engine, chunks: Iterator[list[Configuration]], form: str, workers: int, solo: int) -> Iterator[Part]:
    """The chunks' answers in order: the first ``solo`` configurations here, the rest (if any) in ``workers``
    worker processes."""
    done = 0
    while workers <= 1 or done < solo:
        c = next(chunks, None)
        if c is None:
            return
        done += len(c)
        yield run_chunk(c, form, e)
    first = list(itertools.islice(chunks, 1))
    if not first:  # the work ended with what was answered here: no pool to start
        return
    with ProcessPoolExecutor(workers, initializer=_start, initargs=(e,)) as pool:
        pending: deque[Future[Part]] = deque()
        for c in itertools.chain(first, chunks):
            pending.append(pool.submit(run_chunk, c, form))
            if len(pending) >= 2 * workers:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
