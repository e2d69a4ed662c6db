"""Libraries: folders of ontology extensions, devices, processes, cells and tasks.

A library is a folder with any of ``ontology/`` (TBox extensions in Turtle, RDF/XML or OWL/XML, with their
``owl:imports`` resolved inside the library), ``devices/``,
``processes/``, ``cells/`` and ``tasks/``. The package's own descriptions and ontology are
the *built-in* library. :class:`Knowledge` is everything the use cases need, loaded from
an ordered list of libraries: the taxonomy closure of the combined TBox, the processes
and the catalogue of devices. Two libraries may not define the same process or device id.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.deferred import dataclass
from plugnproduce.description.model import DeviceDescription, ProcessDescription
from plugnproduce.errors import DescriptionError, OntologyError, UnknownName
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy, ontology_files
from plugnproduce.resources import descriptions_path, ontology_path

if TYPE_CHECKING:  # reading Turtle (rdflib) is imported by what reads it: knowledge read back from the cache
    # folder needs none of it
    import rdflib

KINDS = ("ontology", "devices", "processes", "cells", "tasks")
ENV_VARIABLE = "PNP_LIBRARY"


@dataclass(frozen=True)
class Library:
    """One library folder; ``builtin`` for the package's own."""

    root: Path
    builtin: bool = False

    def files(self, kind: str, pattern: str = "*.ttl") -> list[Path]:
        """The files of one kind (``"devices"``, ``"processes"``...) in this library, sorted."""
        if kind == "ontology":  # every Turtle, RDF/XML and OWL/XML file but SHACL shapes, then what they import
            if self.builtin:
                return ontology_files(ontology_path())
            from plugnproduce.ontology.sources import with_imports

            folder = self.root / "ontology"
            return with_imports(ontology_files(folder), self.root) if folder.is_dir() else []
        return _glob(self.root / kind, pattern)

    @property
    def name(self) -> str:
        """How the library is named in messages."""
        return "built-in" if self.builtin else str(self.root)


def _glob(folder: Path, pattern: str) -> list[Path]:
    return sorted(p for p in folder.glob(pattern) if p.is_file()) if folder.is_dir() else []


def builtin_library() -> Library:
    """The package's own descriptions and ontology."""
    return Library(descriptions_path(), builtin=True)


def library_folders(folders: Iterable[str | Path]) -> tuple[Library, ...]:
    """User libraries from folder names; a folder that does not exist is bad input."""
    out: list[Library] = []
    for f in folders:
        p = Path(f).expanduser().resolve()
        if not p.is_dir():
            raise DescriptionError(f"library folder not found; expected a folder with any of {', '.join(KINDS)}", f)
        if p not in {x.root for x in out}:
            out.append(Library(p))
    return tuple(out)


def env_folders(value: str | None) -> list[str]:
    """The folders of a ``PNP_LIBRARY`` value (separated by ``:``; empty parts ignored)."""
    return [part for part in (value or "").split(":") if part.strip()]


_PREFIX = re.compile(r"^\s*(?:@prefix|PREFIX)\s+([A-Za-z][\w.-]*):\s*<([^<>\s]*)>", re.MULTILINE)
"""A prefix a Turtle file declares (``@prefix pnp: <…#> .`` or ``PREFIX pnp: <…#>``)."""


@dataclass(frozen=True)
class Knowledge:
    """The loaded knowledge: taxonomy closure, processes and device catalogue of the libraries.

    What the reasoning layer is given: ``Knowledge((), taxonomy, processes)`` for processes of one's own
    with no library (and so no catalogue)."""

    libraries: tuple[Library, ...]
    taxonomy: Taxonomy
    processes: tuple[ProcessDescription, ...]
    extra_tbox: tuple[Path, ...] = ()
    """TBox files given beside the libraries (an extension being tried out)."""
    left_out: tuple[Path, ...] = ()
    """TBox files of the libraries left out (the state before an extension, for ``pnp impact``)."""
    key: str | None = field(default=None, init=False, compare=False, repr=False)
    """The digest of everything the knowledge was loaded from, when it was read through the cache folder
    (:func:`~plugnproduce.knowledge.cache.cached_knowledge`): two with the same key have the same taxonomy and
    processes, so what is made of them may be kept under it. None for knowledge made otherwise; a copy made by
    :func:`dataclasses.replace` has none."""

    @cached_property
    def processes_by_id(self) -> Mapping[str, ProcessDescription]:
        """The processes by id (their process command), indexed once."""
        return {p.id: p for p in self.processes}

    def process(self, command: str) -> ProcessDescription:
        """The process a command names."""
        found = self.processes_by_id.get(command)
        if found is None:
            raise UnknownName("process command", command, self.processes_by_id)
        return found

    @cached_property
    def devices(self) -> tuple[DeviceDescription, ...]:
        """The catalogue: every device description of every library, sorted by id (each read back from the cache
        folder while its files are unchanged, :mod:`~plugnproduce.knowledge.devicecache`)."""
        from plugnproduce.knowledge.devicecache import device_reader

        read = device_reader(self.taxonomy)
        found = [read(f) for lib in self.libraries for f in lib.files("devices")]
        refuse_duplicates(found, "device")
        return tuple(sorted(found, key=lambda d: d.id))

    def device(self, device_id: str) -> DeviceDescription | None:
        """The catalogue device with this id, if any."""
        return next((d for d in self.devices if d.id == device_id), None)

    def ontology_files(self) -> list[Path]:
        """The TBox files: the ``pnp`` ontology, then every user library's extensions."""
        files = tbox_files(self.libraries) + [f for f in self.extra_tbox if f not in tbox_files(self.libraries)]
        return [f for f in files if f not in self.left_out]

    def tbox(self) -> rdflib.Graph:
        """The combined TBox as written (without the reasoner's closure)."""
        from plugnproduce.ontology.taxonomy import read_tbox

        return read_tbox(self.ontology_files())

    @cached_property
    def prefixes(self) -> dict[str, str]:
        """The prefixes the TBox files bind (``pnp`` → its namespace, and each library's own), by which a device
        may name a concept (``pnp:PartFound``)."""
        out = {"pnp": PNP_IRI}
        for f in self.ontology_files():
            out.update((m[1], m[2]) for m in _PREFIX.finditer(f.read_text(encoding="utf-8", errors="replace")))
        return out

    def cell_files(self) -> list[Path]:
        """Every cell file of the libraries."""
        return [f for lib in self.libraries for f in lib.files("cells", "*.y*ml")]

    def task_files(self) -> list[Path]:
        """Every task file of the libraries."""
        return [f for lib in self.libraries for f in lib.files("tasks", "*.y*ml")]

    def with_libraries(self, extra: Sequence[Library]) -> Knowledge:
        """This knowledge with more libraries (those already loaded are not repeated)."""
        new = [lib for lib in extra if lib not in self.libraries]
        return load_knowledge(self.libraries + tuple(new), self.extra_tbox, self.left_out) if new else self


def refuse_duplicates(items: Sequence[DeviceDescription | ProcessDescription], what: str) -> None:
    """Two descriptions with the same id are an error naming both places."""
    seen: dict[str, DeviceDescription | ProcessDescription] = {}
    for item in items:
        first = seen.setdefault(item.id, item)
        if first is not item:
            raise DescriptionError(
                f"{what} id {item.id!r} is defined twice: here and at {first.where}; "
                "ids must be unique across libraries", item.where.file, item.where.line)


def tbox_files(libraries: Sequence[Library]) -> list[Path]:
    """The ``pnp`` ontology (always: libraries extend it, even without the built-in library) and the
    ``ontology/`` files of the user libraries, in library order."""
    return ontology_files(ontology_path()) + [f for lib in libraries if not lib.builtin for f in lib.files("ontology")]


def _library_root(tbox_file: Path) -> Path:
    """Where a TBox file given on its own resolves imports: its library (``LIB/ontology/x.owl``), else its folder."""
    folder = Path(tbox_file).resolve().parent
    return folder.parent if folder.name == "ontology" else folder


def load_knowledge(libraries: Sequence[Library] | None = None, extra_tbox: Sequence[Path] = (),
                   left_out: Sequence[Path] = ()) -> Knowledge:
    """Load the knowledge of ``libraries`` (default: the built-in one alone).

    The TBox of every library (and ``extra_tbox`` files, but not ``left_out`` ones) is classified
    together; the closure is cached by the combined content. Processes are read from every
    library's ``processes/``.
    """
    from plugnproduce.description.loader import load_process
    from plugnproduce.ontology.sources import with_imports

    libs = tuple(libraries) if libraries is not None else (builtin_library(),)
    extra_tbox = [i for f in extra_tbox for i in with_imports([f], _library_root(f))]
    tbox = [f for f in tbox_files(libs) + [f for f in extra_tbox if f not in tbox_files(libs)] if f not in left_out]
    try:
        taxonomy = load_taxonomy(tbox)
    except OntologyError as exc:
        own = [str(f) for f in tbox if f not in tbox_files((builtin_library(),))]
        if not own:
            raise
        raise OntologyError(f"{exc} with the extension(s) {', '.join(own)}") from exc
    processes = [load_process(f) for lib in libs for f in lib.files("processes")]
    refuse_duplicates(processes, "process")
    return Knowledge(libs, taxonomy, tuple(sorted(processes, key=lambda p: p.id)), tuple(dict.fromkeys(extra_tbox)),
                     tuple(left_out))
