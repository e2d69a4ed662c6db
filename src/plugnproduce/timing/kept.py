"""A task's estimated cycle time, kept in the user's cache folder so that checking an unchanged task again does not
generate its specific process state charts again.

``pnp check`` prints the cycle time of a plausible task, which follows the specific process state charts that code
generation builds: that import and build cost a check more than its reasoning. The estimate is a function of the
package's code, the taxonomy (by its TBox's digest), the task, the cell's devices and the processes the task
runs (each as read, and the content of each device and process state chart) and the role bindings the check
found; it is kept as a pickle named by the digest of all of them, so any edit names another file. A chart that
cannot be read, a file that cannot be read or unpickled, or a cache folder that cannot be written only costs the
estimate. The folder is the user's own, so the pickle is as trusted as the user's files.
"""

from __future__ import annotations

import contextlib
import pickle
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce import folders
from plugnproduce.digests import sha256
from plugnproduce.knowledge.cache import cache_folder, code_digest
from plugnproduce.timing.cycle import CycleTime

if TYPE_CHECKING:
    from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task
    from plugnproduce.knowledge import Knowledge
    from plugnproduce.reasoning import CheckResult

FORMAT = 1
"""The layout of what is kept; another layout is another file name."""
KEEP = 64
"""Estimates kept in the cache folder; older ones are removed when a new one is written."""
_NONE = "no estimate"
"""What is kept for a task whose program cannot be generated."""


def _key(task: Task, cell: Cell, knowledge: Knowledge, result: CheckResult) -> str | None:
    """The digest of everything the estimate follows from; None when a chart cannot be read."""
    h = sha256(f"{FORMAT}\0{code_digest()}\0{knowledge.taxonomy.digest}\0{task!r}\0".encode())
    processes = [knowledge.processes_by_id.get(s.command) for s in task.steps]
    every: list[DeviceDescription | ProcessDescription] = [*cell.devices]
    every += dict.fromkeys(p for p in processes if p is not None)
    for described in every:
        h.update(f"{described!r}\0".encode())
        try:
            h.update(Path(described.chart_file).read_bytes() + b"\0")
        except OSError:
            return None
    h.update(repr(result.bindings()).encode())
    return h.hexdigest()[:32]


def _estimate(task: Task, cell: Cell, knowledge: Knowledge, result: CheckResult) -> CycleTime | None:
    from plugnproduce.timing.tasks import task_cycle_time  # code generation: only when nothing is kept

    return task_cycle_time(task, cell, knowledge, result)


def kept_cycle_time(task: Task, cell: Cell, knowledge: Knowledge, result: CheckResult,
                    folder: Path | None = None) -> CycleTime | None:
    """The estimated cycle time of the plausible ``task`` (checked in ``cell`` as ``result``), read back from the
    cache folder when kept there, else estimated (:func:`~plugnproduce.timing.tasks.task_cycle_time`) and kept;
    None when its program cannot be generated."""
    key = _key(task, cell, knowledge, result) if result.plausible else None
    if key is None:
        return _estimate(task, cell, knowledge, result)
    path = (folder or cache_folder()) / f"cycletime-{key}.pickle"
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        kept = pickle.loads(path.read_bytes())  # noqa: S301 - the user's own cache folder, by content
        if isinstance(kept, CycleTime) or kept == _NONE:
            return kept if isinstance(kept, CycleTime) else None
    estimate = _estimate(task, cell, knowledge, result)
    with contextlib.suppress(OSError, pickle.PicklingError, TypeError, AttributeError):
        folders.keep_newest(path, pickle.dumps(estimate if estimate is not None else _NONE,
                                               protocol=pickle.HIGHEST_PROTOCOL), KEEP)
    return estimate
