"""What the HMI needs from the controller, as small protocols.

The HMI shows a cell that changes (devices plug in and unplug) and runs tasks on it; it is
written against these interfaces, which :mod:`plugnproduce.controller.livecell` and
:mod:`plugnproduce.controller.simcell` (discovery) and :mod:`plugnproduce.controller.runner`
(the executor) implement:

- :class:`CellSource` gives the current :class:`~plugnproduce.description.model.Cell`
  and tells its listeners about every change (plug, unplug, a device's state);
- :class:`PluggableCellSource` is a source the HMI may change itself (a simulated cell);
- :class:`Runner` starts and stops runs of a task and reports their progress as the
  records of the run journal (:mod:`plugnproduce.executor.journal`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, Protocol, runtime_checkable

from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.errors import PlugNProduceError

if TYPE_CHECKING:
    from plugnproduce.service import Replan


@dataclass(frozen=True)
class CellUpdate:
    """Something changed in the cell; ``cell`` is the cell after the change.

    ``plug`` and ``unplug`` name the device; ``refused`` is a device that could not join
    (``reason`` says why); ``state`` reports a device's current chart state (``state``).
    """

    kind: Literal["plug", "unplug", "refused", "state"]
    device: str
    cell: Cell
    reason: str = ""
    state: str | None = None
    location: str = ""
    """For a refused device: the URL it announced itself at."""


CellListener = Callable[[CellUpdate], None]
"""Called for every change; it may be called from any thread and must return quickly."""


@runtime_checkable
class CellSource(Protocol):
    """Where the HMI's cell comes from: discovery (:class:`~plugnproduce.discovery.LiveCell`)."""

    @property
    def cell(self) -> Cell:
        """The cell as it is now."""
        ...

    def subscribe(self, listener: CellListener) -> Callable[[], None]:
        """Call ``listener`` on every change from now on; the returned function unsubscribes."""
        ...

    def refused(self) -> list[dict[str, str]]:
        """The devices refused and not plugged since: each one's ``udn``, ``url`` and ``reason``."""
        ...

    async def start(self) -> None:
        """Begin following the cell (called once when the server starts)."""
        ...

    async def stop(self) -> None:
        """Stop following the cell (called once when the server stops)."""
        ...


@runtime_checkable
class PluggableCellSource(CellSource, Protocol):
    """A cell source the HMI may plug devices into and unplug them from."""

    def catalogue(self) -> list[DeviceDescription]:
        """The devices that can be plugged in (those present included)."""
        ...

    async def plug(self, device_id: str) -> None:
        """Plug in the catalogue device ``device_id`` (UnknownName if unknown, CellChangeRefused if present)."""
        ...

    async def unplug(self, device_id: str) -> None:
        """Unplug the device ``device_id`` (UnknownName if it is not in the cell)."""
        ...


class CellChangeRefused(PlugNProduceError):
    """A plug or unplug the cell source cannot do (the device is there already, or the cell is live)."""


JournalRecord = dict[str, Any]
"""One record of a run journal, as :class:`~plugnproduce.executor.journal.Journal` writes it:
``seq``, ``t``, ``kind`` (``start``, ``step``, ``command``, ``event``, ``state``, ``fault``, ``end``)
and the kind's fields (``step``/``command``; ``device``/``state``; ``fault``/``message``; ``outcome``)."""

RunObserver = Callable[[str, JournalRecord], None]
"""Called with the run id and each journal record as soon as it is written; from any thread."""


class RunRefused(PlugNProduceError):
    """A run that cannot start: another run is active, or the task cannot run in the cell."""


@runtime_checkable
class Runner(Protocol):
    """Starts and stops runs of a task in the cell and reports their progress (the executor implements it)."""

    async def start(self, task: Task, cell: Cell, observer: RunObserver) -> str:
        """Start running ``task`` in ``cell``; return the new run's id at once (RunRefused if it cannot start).

        Every journal record of the run is passed to ``observer`` as it is written; the last
        one is ``end`` with ``outcome`` ``succeeded``, ``failed`` or ``stopped``.
        """
        ...

    async def stop(self, run_id: str) -> None:
        """Stop a run, leaving every device in a safe state (UnknownName if the run is unknown)."""
        ...

    async def replan(self, run_id: str, cell: Cell) -> Replan:
        """What runs on after a failed or stopped run, planned from the states ``cell``'s devices report now."""
        ...

    async def resume(self, run_id: str, cell: Cell, observer: RunObserver, seen: dict[str, str] | None = None) -> str:
        """Re-plan a failed or stopped run and start the plan (``seen``: the states of the plan the operator
        confirmed; RunRefused if they changed); return the new run's id."""
        ...

    def active(self) -> str | None:
        """The id of the run in progress, if any."""
        ...

    def runs(self) -> list[str]:
        """The ids of the runs this runner knows, oldest first."""
        ...

    def journal(self, run_id: str) -> list[JournalRecord]:
        """The journal records of a run so far (UnknownName if the run is unknown)."""
        ...
