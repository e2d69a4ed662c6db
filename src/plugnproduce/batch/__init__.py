"""The batch: every task of a product family checked in many cell configurations drawn from a catalogue.

Each catalogue device is reasoned once (:mod:`plugnproduce.reasoning.checks.abilities`); a configuration is then a
bit mask (:mod:`.feasibility`), the cheapest purchases are searched over masks (:mod:`.purchases`), rows are
written by :mod:`.batches`, spread over a process pool or a Dask cluster (:mod:`.cluster`, :mod:`.clusterpeer`),
and the reasoned catalogue is kept between runs (:mod:`.enginecache`). It uses the reasoning layer and is not
part of it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names

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

_WHERE: dict[str, str] = {
    "batch": ".batches",
    "BATCH_CSV_HEADER": ".batches:CSV_HEADER",
    "BatchRow": ".batches",
    "bounded_lines": ".batches",
    "check_cluster_address": ".cluster:check_address",
    "cluster_mapper": ".cluster",
    "ClusterAccess": ".clusterpeer",
    "ClusterError": ".clusterpeer",
    "Configuration": ".batches",
    "configurations_from": ".batches",
    "Engine": ".batches",
    "engine": ".batches",
    "generate": ".batches",
    "Purchase": ".purchases",
    "read_configurations": ".batches",
    "report": ".batches",
    "report_from": ".batches",
}
"""Each name this package offers: the module it is defined in (below this package) and its name there."""


__getattr__, __dir__ = lazy_names(__name__, _WHERE)  # loads neither clingo nor owlready2 nor any part until used


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
