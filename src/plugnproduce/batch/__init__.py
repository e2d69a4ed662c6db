"""The batch: every task of a product family checked in many cell configurations drawn from a catalogue.

Each catalogue device is reasoned once (:mod:`plugnproduce.reasoning.checks.abilities`); a configuration is then a
bit mask (:mod:`.feasibility`), the cheapest purchases are searched over masks (:mod:`.purchases`), rows are
written by :mod:`.batches`, spread over a process pool or a Dask cluster (:mod:`.cluster`, :mod:`.clusterpeer`),
and the reasoned catalogue is kept between runs (:mod:`.enginecache`). It uses the reasoning layer and is not
part of it.
"""

from __future__ import annotations

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
