"""Runs and reports: the runs folder, run ids, and the journals of past runs."""

from __future__ import annotations

import secrets
import time
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce import folders
from plugnproduce.errors import PlugNProduceError, UnknownName

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce.executor.history import RunSummary
    from plugnproduce.executor.journal import RunRecord


def runs_folder() -> Path:
    """Where run journals go unless told otherwise: ``PNP_RUNS``, else ``runs`` in the user's state folder
    (:func:`plugnproduce.folders.runs_folder`)."""
    return folders.runs_folder()


def new_run_id(task_name: str) -> str:
    """A run id that sorts by start time: ``20261123-101500-bin-picking-1a2b``."""
    return f"{time.strftime('%Y%m%d-%H%M%S')}-{task_name}-{secrets.token_hex(2)}"


def report(run: str | Path | None = None) -> RunRecord:
    """A run's journal, by path or by run id (in :func:`runs_folder`); without either, the latest run's."""
    from plugnproduce.executor.journal import read_journal

    if run is None:
        past = runs()
        if not past:
            raise PlugNProduceError(f"no runs yet in {runs_folder()}")
        return read_journal(past[0].path)
    path = Path(run)
    if not path.exists() and not path.suffix:
        path = runs_folder() / f"{run}.jsonl"
        if not path.exists():
            raise UnknownName("run", str(run), (r.id for r in runs()))
    return read_journal(path)


def runs() -> list[RunSummary]:
    """The past runs in :func:`runs_folder`, newest first."""
    from plugnproduce.executor.history import list_runs

    return list_runs(runs_folder())
