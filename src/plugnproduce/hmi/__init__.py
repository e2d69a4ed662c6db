"""The Generic HMI (paper section 5): an HTTP API and a web page over the controller's use cases.

:func:`create_app` builds the FastAPI application over a :class:`CellSource` (where the
cell comes from) and a :class:`Runner` (who runs tasks); :class:`FileCellSource` and
:class:`ModelRunner` implement them without devices until discovery and the executor
take their place. ``pnp serve`` starts it.
"""

from __future__ import annotations

from plugnproduce.hmi.app import create_app
from plugnproduce.hmi.filecell import FileCellSource
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
from plugnproduce.hmi.modelrunner import ModelRunner

__all__ = [
    "CellChangeRefused",
    "CellListener",
    "CellSource",
    "CellUpdate",
    "FileCellSource",
    "JournalRecord",
    "ModelRunner",
    "PluggableCellSource",
    "RunObserver",
    "RunRefused",
    "Runner",
    "create_app",
]
