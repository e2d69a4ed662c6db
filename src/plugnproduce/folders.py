"""The user's folders the controller writes to, where the platform keeps them (platformdirs).

- the **cache folder** (``~/.cache/plugnproduce`` on Linux, or ``$XDG_CACHE_HOME/plugnproduce``): the
  taxonomy's closures, the unit table, the batch engines, the simulated cell's control file, the kept help;
- the **runs folder** (``~/.local/state/plugnproduce/runs`` on Linux, or under ``$XDG_STATE_HOME``): the
  run journals, unless ``PNP_RUNS`` names another folder.
"""

from __future__ import annotations

import os
from pathlib import Path

import platformdirs

APP = "plugnproduce"
"""The folders' name under the platform's cache and state folders."""
RUNS_VARIABLE = "PNP_RUNS"
"""The environment variable that names the runs folder instead."""


def cache_folder() -> Path:
    """The user's cache folder for plugnproduce."""
    return Path(platformdirs.user_cache_dir(APP))


def runs_folder() -> Path:
    """Where run journals go unless told otherwise: ``PNP_RUNS``, else ``runs`` in the user's state folder."""
    given = os.environ.get(RUNS_VARIABLE)
    return Path(given) if given else Path(platformdirs.user_state_dir(APP)) / "runs"
