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

from typing import TYPE_CHECKING

from plugnproduce.lazy import lazy_names

if TYPE_CHECKING:
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
    from plugnproduce.controller.resume import (
        NoCell,
        Resumed,
        SimulatedResume,
        continue_run,
        replan_live,
        resume_run,
    )
    from plugnproduce.controller.run import (
        DEFAULT_BIN_PARTS,
        DISCOVERY_SECONDS,
        SIMULATED_DISCOVERY_SECONDS,
        DevicesMissing,
        StateNotReported,
        default_bin_parts,
        find_devices,
        live_cell,
        planned_run,
        reported_states,
        run_task,
        start_run,
    )
    from plugnproduce.controller.runner import ExecutorRunner
    from plugnproduce.controller.simcell import SimulatedCellSource
    from plugnproduce.controller.teaching import read_taught, teach
    from plugnproduce.discovery import CellChange, LiveCell
    from plugnproduce.executor.run import TaskRun
    from plugnproduce.protocols.interface import chosen_address
    from plugnproduce.protocols.upnp import network_from_env
    from plugnproduce.sim.bin import SimulatedBin

_WHERE = {
    **dict.fromkeys(("CellChangeRefused", "CellListener", "CellSource", "CellUpdate", "JournalRecord",
                     "PluggableCellSource", "Runner", "RunObserver", "RunRefused"),
                    "plugnproduce.controller.interfaces"),
    "LiveCellSource": "plugnproduce.controller.livecell",
    **dict.fromkeys(("NoCell", "Resumed", "SimulatedResume", "continue_run", "replan_live", "resume_run"),
                    "plugnproduce.controller.resume"),
    **dict.fromkeys(("read_taught", "teach"), "plugnproduce.controller.teaching"),
    **dict.fromkeys(("DEFAULT_BIN_PARTS", "DISCOVERY_SECONDS", "SIMULATED_DISCOVERY_SECONDS", "DevicesMissing",
                     "StateNotReported", "default_bin_parts", "find_devices", "live_cell", "planned_run",
                     "reported_states", "run_task", "start_run"), "plugnproduce.controller.run"),
    "ExecutorRunner": "plugnproduce.controller.runner",
    "SimulatedCellSource": "plugnproduce.controller.simcell",
    **dict.fromkeys(("CellChange", "LiveCell"), "plugnproduce.discovery"),
    "TaskRun": "plugnproduce.executor.run",
    "chosen_address": "plugnproduce.protocols.interface",
    "network_from_env": "plugnproduce.protocols.upnp",
    "SimulatedBin": "plugnproduce.sim.bin",
}
"""Where each name of the controller lives: it is imported on first use, so that importing one module of the
controller (``pnp sim plug`` needs :mod:`.devices` alone) loads no network stack."""


__getattr__, __dir__ = lazy_names(__name__, _WHERE)


__all__ = [
    "DEFAULT_BIN_PARTS",
    "DISCOVERY_SECONDS",
    "SIMULATED_DISCOVERY_SECONDS",
    "CellChange",
    "CellChangeRefused",
    "CellListener",
    "CellSource",
    "CellUpdate",
    "DevicesMissing",
    "ExecutorRunner",
    "JournalRecord",
    "LiveCell",
    "LiveCellSource",
    "NoCell",
    "PluggableCellSource",
    "Resumed",
    "RunObserver",
    "RunRefused",
    "Runner",
    "SimulatedBin",
    "SimulatedCellSource",
    "SimulatedResume",
    "StateNotReported",
    "TaskRun",
    "chosen_address",
    "continue_run",
    "default_bin_parts",
    "find_devices",
    "live_cell",
    "network_from_env",
    "planned_run",
    "read_taught",
    "replan_live",
    "reported_states",
    "resume_run",
    "run_task",
    "start_run",
    "teach",
]
