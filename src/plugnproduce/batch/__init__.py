"""The batch: every task of a product family checked in many cell configurations drawn from a catalogue.

Each catalogue device is reasoned once (:mod:`plugnproduce.reasoning.checks.abilities`); a configuration is then a
bit mask (:mod:`.feasibility`), the cheapest purchases are searched over masks (:mod:`.purchases`), rows are
written by :mod:`.batches`, spread over a process pool or a Dask cluster (:mod:`.cluster`, :mod:`.clusterpeer`),
and the reasoned catalogue is kept between runs (:mod:`.enginecache`). It uses the reasoning layer and is not
part of it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from plugnproduce.batch.batches import CSV_HEADER as BATCH_CSV_HEADER
    from plugnproduce.batch.batches import (
        BatchRow,
        Configuration,
        Engine,
        batch,
        bounded_lines,
        configurations_from,
        engine,
        generate,
        read_configurations,
        report,
        report_from,
    )
    from plugnproduce.batch.cluster import check_address as check_cluster_address
    from plugnproduce.batch.cluster import cluster_mapper
    from plugnproduce.batch.clusterpeer import ClusterAccess, ClusterError
    from plugnproduce.batch.purchases import Purchase

_WHERE: dict[str, tuple[str, str]] = {
    "batch": ("batches", "batch"),
    "BATCH_CSV_HEADER": ("batches", "CSV_HEADER"),
    "BatchRow": ("batches", "BatchRow"),
    "bounded_lines": ("batches", "bounded_lines"),
    "check_cluster_address": ("cluster", "check_address"),
    "cluster_mapper": ("cluster", "cluster_mapper"),
    "ClusterAccess": ("clusterpeer", "ClusterAccess"),
    "ClusterError": ("clusterpeer", "ClusterError"),
    "Configuration": ("batches", "Configuration"),
    "configurations_from": ("batches", "configurations_from"),
    "Engine": ("batches", "Engine"),
    "engine": ("batches", "engine"),
    "generate": ("batches", "generate"),
    "Purchase": ("purchases", "Purchase"),
    "read_configurations": ("batches", "read_configurations"),
    "report": ("batches", "report"),
    "report_from": ("batches", "report_from"),
}
"""Each name this package offers: the module it is defined in (below this package) and its name there."""


def __getattr__(name: str) -> object:
    """Import the module that defines ``name`` on its first use (:pep:`562`), so that importing the package loads
    neither clingo nor owlready2 nor any of its parts."""
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module, attr = _WHERE[name]
    value = getattr(importlib.import_module(f"{__name__}.{module}"), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_WHERE})


__all__ = [
    "BATCH_CSV_HEADER",
    "BatchRow",
    "ClusterAccess",
    "ClusterError",
    "Configuration",
    "Engine",
    "Purchase",
    "batch",
    "bounded_lines",
    "check_cluster_address",
    "cluster_mapper",
    "configurations_from",
    "engine",
    "generate",
    "read_configurations",
    "report",
    "report_from",
]
