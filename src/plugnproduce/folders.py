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


def keep_newest(path: Path, data: bytes, keep: int) -> None:
    """Write ``data`` to ``path`` whole and at once (a concurrent reader sees no half file), then keep only the
    newest ``keep`` files of its kind beside it: those named like it up to its first ``-``, with its suffix."""
    import tempfile

    kind = path.name.split("-", 1)[0]
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{kind}-", dir=path.parent)
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)
    old = sorted(path.parent.glob(f"{kind}-*{path.suffix}"), key=lambda p: p.stat().st_mtime, reverse=True)[keep:]
    for p in old:
        p.unlink(missing_ok=True)
