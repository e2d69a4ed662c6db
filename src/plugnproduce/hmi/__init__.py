"""The Generic HMI (paper section 5): an HTTP API and a web page over the controller's use cases.

:func:`create_app` builds the FastAPI application over a :class:`CellSource` (where the
cell comes from) and a :class:`Runner` (who runs tasks): :class:`LiveCellSource` follows
discovery, :class:`SimulatedCellSource` follows a simulated cell through discovery and
plugs its devices, and :class:`ExecutorRunner` runs tasks on the devices with the executor:
they are the controller's (:mod:`plugnproduce.controller`), named here for the HMI's users.
``pnp serve`` starts it.
"""

from __future__ import annotations

from plugnproduce.controller import (
    ExecutorRunner,
    LiveCellSource,
    SimulatedCellSource,
)
from plugnproduce.controller.interfaces import (
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
from plugnproduce.hmi.app import create_app

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
