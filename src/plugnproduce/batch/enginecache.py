"""The batch's reasoned catalogue, kept in the user's cache folder so that a batch over unchanged files starts at once.

Before it answers its first configuration, ``pnp batch`` reads the libraries' processes, every catalogue device
(Turtle and its chart) and the tasks, and reasons over them once (:func:`plugnproduce.reasoning.engine`): most
of its fixed cost, the same every run over the same files. The engine it builds is kept as a pickle named by
the digest of everything it was reasoned from: the contents of the package's code, its rules and ontology, every
file of the libraries, the catalogue folder and the task files, and the number of purchases asked for. A change
to any of them names another file; a file that cannot be read or unpickled is rebuilt. The folder is the
user's own (as for the taxonomy's closure), so the pickle is as trusted as the user's files.
"""

from __future__ import annotations

import contextlib
import hashlib
import pickle
import sys
from collections.abc import Callable, Iterable
from pathlib import Path

import plugnproduce
from plugnproduce import folders
from plugnproduce.knowledge.libraries import Library, tbox_files
from plugnproduce.resources import rules_path

KEEP = 8
"""Engines kept in the cache folder; older ones are removed when a new one is written."""


def cache_folder() -> Path:
    """Where the engines are kept: the user's cache folder, beside the taxonomy's closures."""
    return folders.cache_folder()


def _files(root: Path, pattern: str = "*") -> list[Path]:
    return sorted(p for p in root.rglob(pattern) if p.is_file() and "__pycache__" not in p.parts)


def digest(libraries: Iterable[Library], catalogue: Path | None, tasks: Iterable[Path], top: int) -> str | None:
    """The digest of what a batch engine is reasoned from; None when a file cannot be read (the batch then
    reads everything itself and says what is wrong)."""
    libs = tuple(libraries)
    files = [*_files(Path(plugnproduce.__file__).parent, "*.py"), *_files(rules_path()), *tbox_files(libs)]
    files += [f for lib in libs for f in _files(lib.root)]
    files += _files(catalogue) if catalogue is not None and catalogue.is_dir() else []
    h = hashlib.sha256(f"{sys.version}\0{top}\0{catalogue}\0".encode())
    try:
        for f in [*files, *tasks]:
            h.update(f"{f}\0".encode() + Path(f).read_bytes() + b"\0")
    except OSError:
        return None
    return h.hexdigest()[:32]


def cached(key: str | None, build: Callable[[], object], folder: Path | None = None) -> object:
    """The object kept under ``key``, or ``build()``'s, then kept (without a key: built, not kept)."""
    if key is None:
        return build()
    path = (folder or cache_folder()) / f"batch-{key}.pickle"
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        return pickle.loads(path.read_bytes())  # noqa: S301 - the user's own cache folder, named by content
    value = build()
    with contextlib.suppress(OSError):  # a cache that cannot be written only costs time
        folders.keep_newest(path, pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL), KEEP)
    return value


