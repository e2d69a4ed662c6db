"""The parsed knowledge, kept in the user's cache folder so that a command over unchanged libraries reads it back.

Every command that reasons first loads its libraries: the taxonomy's closure (itself cached by the TBox's
content) and every process description, Turtle and general process state chart, parsed again each time,
though they rarely change between two commands. The loaded :class:`~.libraries.Knowledge` is kept as a pickle
named by the digest of everything it was read from: the package's code (each module's name, size and time of
change, as the kept help is named), the ontology files and every file of every library, by content. A process
whose chart lies outside its library has that file's content checked when the pickle is read. A change to any
of them names another file, or fails the check; a file that cannot be read or unpickled is loaded again. The
folder is the user's own (as for the taxonomy's closure and the batch's engines), so the pickle is as trusted
as the user's files.
"""

from __future__ import annotations

import contextlib
import pickle
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from plugnproduce import folders
from plugnproduce.digests import sha256
from plugnproduce.folders import code_digest as code_digest
from plugnproduce.knowledge.libraries import Knowledge, Library
from plugnproduce.ontology.taxonomy import ontology_files
from plugnproduce.resources import ontology_path

FORMAT = 1
"""The layout of what is kept; another layout is another file name."""
KEEP = 8
"""Knowledge files kept in the cache folder; older ones are removed when a new one is written."""


def cache_folder() -> Path:
    """The user's cache folder, beside the taxonomy's closures and the batch's engines."""
    return folders.cache_folder()


def _files(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts)


def digest(libraries: Sequence[Library]) -> str | None:
    """The digest of what the knowledge of ``libraries`` is loaded from; None when a file cannot be read (it is
    then loaded, and what is wrong said, as without a cache)."""
    h = sha256(f"{FORMAT}\0{code_digest()}\0".encode())
    try:
        # the pnp ontology, then every file of every library: the TBox files a library imports lie inside it, so
        # they are among its files without resolving its imports (which would mean reading RDF)
        for f in [*ontology_files(ontology_path()), *(f for lib in libraries for f in _files(lib.root))]:
            h.update(f"{f}\0".encode() + Path(f).read_bytes() + b"\0")
    except OSError:
        return None
    h.update("\0".join(f"{lib.root}\0{lib.builtin}" for lib in libraries).encode())
    return h.hexdigest()[:32]


def _outside(knowledge: Knowledge) -> dict[str, bytes]:
    """The content of each process's chart file that lies outside every library (read again when kept)."""
    roots = [lib.root.resolve() for lib in knowledge.libraries]
    charts = {Path(p.chart_file).resolve() for p in knowledge.processes if p.chart_file}
    return {str(c): c.read_bytes() for c in sorted(charts) if not any(c.is_relative_to(r) for r in roots)}


def _unchanged(outside: dict[str, bytes]) -> bool:
    try:
        return all(Path(f).read_bytes() == data for f, data in outside.items())
    except OSError:
        return False


def cached_knowledge(libraries: Sequence[Library], load: Callable[[], Knowledge],
                     folder: Path | None = None) -> Knowledge:
    """The knowledge of ``libraries``, read from the cache folder when kept there, else ``load()``'s, then kept."""
    key = digest(libraries)
    if key is None:
        return load()
    path = (folder or cache_folder()) / f"knowledge-{key}.pickle"
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        kept, outside = pickle.loads(path.read_bytes())  # noqa: S301 - the user's own cache folder, by content
        if isinstance(kept, Knowledge) and _unchanged(outside):
            return _keyed(kept, _own_key(key, outside), path.parent)
    knowledge = load()
    with contextlib.suppress(OSError, pickle.PicklingError, TypeError, AttributeError):
        outside = _outside(knowledge)
        _keyed(knowledge, _own_key(key, outside), path.parent)
        data = pickle.dumps((knowledge, outside), protocol=pickle.HIGHEST_PROTOCOL)
        folders.keep_newest(path, data, KEEP)
    return knowledge


_FOLDERS: dict[str, Path] = {}
"""The cache folder of each knowledge key this process read or kept, where what is made of it is kept too."""


def _keyed(knowledge: Knowledge, key: str, folder: Path) -> Knowledge:
    object.__setattr__(knowledge, "key", key)  # set once, as it is read: the knowledge is frozen for everyone else
    _FOLDERS[key] = folder
    return knowledge


KEEP_MADE = 64
"""Texts made of knowledge alone (:func:`kept_for`) kept in the cache folder."""


def kept_for(knowledge: Knowledge, what: str, make: Callable[[], str]) -> str:
    """``make()``: a text made of ``knowledge``'s taxonomy and processes alone, which ``what`` names (the processes'
    ASP facts), read back from the cache folder under the knowledge's key when kept there, else made and kept.
    Made, and not kept, for knowledge without a key (:attr:`~.libraries.Knowledge.key`)."""
    folder = _FOLDERS.get(knowledge.key) if knowledge.key is not None else None
    if folder is None:
        return make()
    name = sha256(f"{FORMAT}\0{knowledge.key}\0{what}".encode()).hexdigest()[:32]
    return folders.made_once(folder / f"made-{name}.pickle", make, KEEP_MADE)


def _own_key(key: str, outside: dict[str, bytes]) -> str:
    """The knowledge's own key (:attr:`~.libraries.Knowledge.key`): the digest of its libraries and of the content
    of each chart it read outside them (which the digest alone does not name)."""
    h = sha256(key.encode())
    for f, data in sorted(outside.items()):
        h.update(f"\0{f}\0{len(data)}\0".encode() + data)
    return h.hexdigest()[:32]


def kept_files(folder: Path | None = None) -> Iterable[Path]:
    """The knowledge files kept in the cache folder."""
    return sorted((folder or cache_folder()).glob("knowledge-*.pickle"))
