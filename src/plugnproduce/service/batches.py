"""Batch: the feasibility of many configurations of catalogue devices, streamed."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import DeviceDescription, Task
from plugnproduce.knowledge import Knowledge, builtin_library, library_folders
from plugnproduce.lazy import lazy_module
from plugnproduce.service.descriptions import (
    _devices,
    _k,
    as_task,
    catalogue,
    knowledge,
    task,
)

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce import batch as batching
else:
    batching = lazy_module("plugnproduce.batch")  # a validation needs no batch engine


def batch(
    configurations: Iterable[batching.Configuration] | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    tasks: list[Task | str | Path] | None = None,
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    knowledge: Knowledge | None = None,
    top: int = 1,
    cluster: str | batching.ClusterAccess | None = None,
) -> Iterator[batching.BatchRow]:
    """Feasibility of many configurations (an iterable, or a JSONL/CSV file of device lists) of catalogue
    devices, streamed in order: per configuration the offered processes, the plausible tasks, and when
    some task is not, the ``top`` cheapest sets of catalogue devices to add (or why none suffices).
    ``cluster``: a Dask scheduler address (``tcp://host:8786``) or ``local:N`` (N local worker processes), or a
    :class:`~plugnproduce.batch.ClusterAccess` with its connect timeout and TLS files; a cluster address is
    trusted code execution (it runs what the batch sends, and what comes back is unpickled)."""
    k = _k(knowledge)
    devices = _devices(catalogue_or_folder, k)
    configs = (batching.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = batching.cluster_mapper(cluster) if cluster is not None else None
    return batching.batch(configs, devices, [as_task(t) for t in tasks or []], k,
                           workers=workers, progress=progress, top=top, mapper=mapper)


def batch_report(
    configurations: Iterable[batching.Configuration] | str | Path,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    tasks: list[Task | str | Path] | None = None,
    form: str = "jsonl",
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    knowledge: Knowledge | None = None,
    top: int = 1,
    cluster: str | batching.ClusterAccess | None = None,
    tally: dict[str, int] | None = None,
) -> Iterator[str]:
    """:func:`batch`'s answers as report text (JSONL, or CSV rows with ``form`` "csv"), a chunk at a time,
    made by the workers: what ``pnp batch`` writes. ``tally`` counts the configurations written by outcome
    (all plausible, a purchase, a role to bind, nothing helps)."""
    k = _k(knowledge)
    devices = _devices(catalogue_or_folder, k)
    configs = (batching.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = batching.cluster_mapper(cluster) if cluster is not None else None
    return batching.report(configs, devices, [as_task(t) for t in tasks or []], k,
                            form=form, workers=workers, progress=progress, top=top, mapper=mapper, tally=tally)


def batch_engine(
    catalogue_folder: str | Path | None,
    tasks: list[str | Path],
    top: int = 1,
    libraries: tuple[str | Path, ...] = (),
    builtin: bool = True,
) -> batching.Engine:
    """What a batch over files reasons once (the catalogue devices and tasks against the libraries' processes),
    kept in the user's cache folder: a later batch over the same files, unchanged, reads it back instead of
    reading and reasoning over every description again (:mod:`.batch.enginecache`)."""
    from plugnproduce.batch import enginecache

    folder = Path(catalogue_folder) if catalogue_folder is not None else None
    libs = ((builtin_library(),) if builtin else ()) + library_folders(libraries)

    def build() -> batching.Engine:
        k = knowledge(libraries, builtin)
        return batching.engine(catalogue(folder, k), [task(p) for p in tasks], k, top)

    key = enginecache.digest(libs, folder, [Path(p) for p in tasks], top)
    found = enginecache.cached(key, build)
    return found if isinstance(found, batching.Engine) else build()


def batch_report_from(
    engine: batching.Engine,
    configurations: Iterable[batching.Configuration] | str | Path,
    form: str = "jsonl",
    workers: int = 2,
    progress: Callable[[int], None] | None = None,
    cluster: str | batching.ClusterAccess | None = None,
    tally: dict[str, int] | None = None,
) -> Iterator[str]:
    """:func:`batch_report` by an engine already built (:func:`batch_engine`)."""
    configs = (batching.read_configurations(configurations) if isinstance(configurations, str | Path)
               else configurations)
    mapper = batching.cluster_mapper(cluster) if cluster is not None else None
    return batching.report_from(engine, configs, form=form, workers=workers, progress=progress, mapper=mapper,
                                 tally=tally)


def generate_configurations(
    count: int,
    sizes: tuple[int, int],
    seed: int,
    catalogue_or_folder: list[DeviceDescription] | str | Path | None = None,
    knowledge: Knowledge | None = None,
) -> Iterator[batching.Configuration]:
    """``count`` random configurations of ``sizes[0]``-``sizes[1]`` distinct catalogue devices, generated lazily."""
    return batching.generate(_devices(catalogue_or_folder, _k(knowledge)), count, sizes, seed)


def batch_cycle_times(
    engine: batching.Engine,
    configurations: Iterable[batching.Configuration],
    catalogue_folder: str | Path | None,
    tasks: list[str | Path],
    libraries: tuple[str | Path, ...] = (),
    builtin: bool = True,
) -> Iterator[dict[str, object]]:
    """:func:`batch_report_from`'s JSONL rows in this process, each with the configuration's ``cost`` and per task
    its estimated ``cycle_time`` (seconds; null where it is not plausible), estimated once per set of devices the
    tasks bind (:class:`~plugnproduce.batch.timings.CycleTimes`)."""
    from plugnproduce.batch.timings import CycleTimes

    k = knowledge(libraries, builtin)
    folder = Path(catalogue_folder) if catalogue_folder is not None else None
    times = CycleTimes(engine, catalogue(folder, k), [task(p) for p in tasks], k)
    for config in configurations:
        yield times.annotate(engine.line(config), config)


def pareto_front(rows: Iterable[dict[str, object]]) -> list[dict[str, object]]:
    """Of :func:`batch_cycle_times`'s rows, the configurations in which every task is plausible that no other beats
    in both cost and cycle time (summed over the tasks), cheapest first: ``{config, devices, cost, cycle_time}``."""
    from plugnproduce.batch.timings import ParetoFront

    front = ParetoFront()
    for row in rows:
        front.add(row)
    return [p.to_json() for p in front.front()]
