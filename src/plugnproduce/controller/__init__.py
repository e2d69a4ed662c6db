"""The controller: what runs a cell.

- the cell sources: :class:`LiveCellSource` follows discovery, :class:`SimulatedCellSource` follows a
  simulated cell through discovery and plugs its devices (:mod:`.interfaces` says what a source is);
- the runs: :func:`run_task` finds a cell's devices and runs a task on them (``pnp run``), and
  :class:`ExecutorRunner` runs tasks on a cell source's devices, one at a time (the HMI);
- resume: :func:`resume_run` re-plans a stopped run from the devices' states and continues it (``pnp resume``);
- teach-in: :func:`teach` reads a value a device reports and holds it to its contracts (``pnp teach``);
- the live cell: :func:`live_cell` asks each device its state (``pnp check --live``).

The faces (``cli``, ``hmi``) use it and the service; it uses the service and the concepts (discovery,
protocols, executor, sim).
"""

from __future__ import annotations

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
from plugnproduce.controller.livecell import LiveCellSource
from plugnproduce.controller.resume import NoCell, Resumed, SimulatedResume, continue_run, replan_live, resume_run
from plugnproduce.controller.run import (
    DEFAULT_BIN_PARTS,
    DISCOVERY_SECONDS,
    SIMULATED_DISCOVERY_SECONDS,
    DevicesMissing,
    StateNotReported,
    default_bin_parts,
    find_devices,
    live_cell,
    reported_states,
    run_task,
    start_run,
)
from plugnproduce.controller.runner import ExecutorRunner
from plugnproduce.controller.simcell import SimulatedCellSource
from plugnproduce.controller.teach import read_taught, teach

__all__ = [
    "DEFAULT_BIN_PARTS",
    "DISCOVERY_SECONDS",
    "SIMULATED_DISCOVERY_SECONDS",
    "CellChangeRefused",
    "CellListener",
    "CellSource",
    "CellUpdate",
    "DevicesMissing",
    "ExecutorRunner",
    "JournalRecord",
    "LiveCellSource",
    "NoCell",
    "PluggableCellSource",
    "Resumed",
    "RunObserver",
    "RunRefused",
    "Runner",
    "SimulatedCellSource",
    "SimulatedResume",
    "StateNotReported",
    "continue_run",
    "default_bin_parts",
    "find_devices",
    "live_cell",
    "replan_live",
    "read_taught",
    "reported_states",
    "resume_run",
    "run_task",
    "start_run",
    "teach",
]
