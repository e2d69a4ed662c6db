"""The user's folders the controller writes to, where the platform keeps them (platformdirs).

- the **cache folder** (``~/.cache/plugnproduce`` on Linux, or ``$XDG_CACHE_HOME/plugnproduce``): the
  taxonomy's closures, the unit table, the batch engines, the simulated cell's control file, the kept help,
  OPC UA's standard address space;
  the parsed knowledge, devices, cell and task files and cycle time estimates (:func:`kept`);
- the **runs folder** (``~/.local/state/plugnproduce/runs`` on Linux, or under ``$XDG_STATE_HOME``): the
  run journals, unless ``PNP_RUNS`` names another folder.
"""

from __future__ import annotations

import contextlib
import functools
import os
import pickle
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from plugnproduce.digests import sha256

T = TypeVar("T")

APP = "plugnproduce"
"""The folders' name under the platform's cache and state folders."""
RUNS_VARIABLE = "PNP_RUNS"
"""The environment variable that names the runs folder instead."""


def cache_folder() -> Path:
    """The user's cache folder for plugnproduce.

    On Linux platformdirs names it from ``XDG_CACHE_HOME`` (when absolute) or ``~/.cache``; that rule is followed
    here without importing platformdirs, which costs every command that reads its cache a few per cent of a warm
    answer (``tests/test_folders.py`` holds the two to the same answer). Elsewhere, platformdirs answers.
    """
    if sys.platform.startswith("linux"):
        xdg = os.environ.get("XDG_CACHE_HOME", "")
        return Path(xdg if os.path.isabs(xdg) else os.path.expanduser("~/.cache")) / APP
    import platformdirs

    return Path(platformdirs.user_cache_dir(APP))


def runs_folder() -> Path:
    """Where run journals go unless told otherwise: ``PNP_RUNS``, else ``runs`` in the user's state folder."""
    given = os.environ.get(RUNS_VARIABLE)
    if given:
        return Path(given)
    import platformdirs

    return Path(platformdirs.user_state_dir(APP)) / "runs"


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


@functools.lru_cache(maxsize=1)
def code_digest() -> str:
    """The package's code and the interpreter's version, by each module's name, size and time of change (reading
    it all would cost more than it saves); looked at once per process. What is kept from the code's work is named
    by it, so another version of the code never reads it."""
    h = sha256(f"{sys.version}\0".encode())
    here = os.path.dirname(__file__)
    for folder, dirs, names in os.walk(here):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        inside = folder[len(here):].lstrip(os.sep)  # the folder relative to the package (os.path.relpath, cheaper)
        for name in sorted(n for n in names if n.endswith(".py")):
            stat = os.stat(os.path.join(folder, name))
            h.update(f"{os.path.join(inside, name)}\0{stat.st_size}\0{stat.st_mtime_ns}\0".encode())
    return h.hexdigest()


KEEP_PARSED = 64
"""Parsed files of each kind kept in the cache folder."""


def kept(kind: str, source: Path, parse: Callable[[Path], T], fits: Callable[[object], bool],
         folder: Path | None = None) -> T:
    """``parse(source)``, read back from the cache folder when kept there for the same code, path and content (a
    pickle named by their digest), else parsed and kept. ``fits`` tells whether what is read back is such a value.
    A file that cannot be read is parsed (which says what is wrong); bad input is never kept; a kept file that
    cannot be read or unpickled is parsed again; a folder that cannot be written only costs the next parse. The
    folder is the user's own, so the pickle is as trusted as the user's files."""
    try:
        data = source.read_bytes()
    except OSError:
        return parse(source)
    h = sha256(f"{kind}\0{code_digest()}\0{source}\0{source.resolve()}\0".encode())  # as named, and where
    # it is: what a file names relative to itself or the working folder is read back as that file meant it
    h.update(data)
    path = (folder or cache_folder()) / f"{kind}-{h.hexdigest()[:32]}.pickle"
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        value = pickle.loads(path.read_bytes())  # noqa: S301 - the user's own cache folder, by content
        if fits(value):
            return value  # type: ignore[no-any-return]
    value = parse(source)
    with contextlib.suppress(OSError, pickle.PicklingError, TypeError, AttributeError):
        keep_newest(path, pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL), KEEP_PARSED)
    return value


def made_once(path: Path, make: Callable[[], str], keep: int) -> str:
    """``make()``, read back from ``path`` when kept there, else made and kept there (with the newest ``keep`` of
    its kind, :func:`keep_newest`). ``path`` is named by the digest of everything ``make`` depends on; a kept file
    that cannot be read or is not what was kept is made again, and a folder that cannot be written costs only the
    making. The folder is the user's own, so the pickle is as trusted as the user's files."""
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        name, text = pickle.loads(path.read_bytes())  # noqa: S301 - the user's own cache folder, by content
        if name == path.name and isinstance(text, str):
            return text
    text = make()
    with contextlib.suppress(OSError, pickle.PicklingError):
        keep_newest(path, pickle.dumps((path.name, text), protocol=pickle.HIGHEST_PROTOCOL), keep)
    return text
