"""The Generic HMI (paper section 5): an HTTP API and a web page over the controller's use cases.

:func:`create_app` builds the FastAPI application over a :class:`CellSource` (where the
cell comes from) and a :class:`Runner` (who runs tasks): :class:`LiveCellSource` follows
discovery, :class:`SimulatedCellSource` follows a simulated cell through discovery and
plugs its devices, and :class:`ExecutorRunner` runs tasks on the devices with the executor.
``pnp serve`` starts it.
"""

from __future__ import annotations

from plugnproduce.hmi.app import create_app
from plugnproduce.hmi.executorrunner import ExecutorRunner
from plugnproduce.hmi.interfaces import (
    CellChangeRefused,
    CellListener,
    CellSource,
    CellUpdate,
    JournalRecord,
    PluggableCellSource,
    Runner,
    RunObserver,
    RunRefused,
)
from plugnproduce.hmi.livecell import LiveCellSource
from plugnproduce.hmi.simcell import SimulatedCellSource

__all__ = [
    "CellChangeRefused",
    "CellListener",
    "CellSource",
    "CellUpdate",
    "ExecutorRunner",
    "JournalRecord",
    "LiveCellSource",
    "PluggableCellSource",
    "RunObserver",
    "RunRefused",
    "Runner",
    "SimulatedCellSource",
    "create_app",
]
