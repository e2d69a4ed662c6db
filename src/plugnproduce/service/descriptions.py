"""Knowledge and descriptions: load the libraries, read cells, tasks and catalogues, validate them, and what
an ontology extension changes."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

from plugnproduce.description.cellfile import kept_cell_device_files, kept_cell_libraries, load_cell
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.folders import kept
from plugnproduce.knowledge import Knowledge, Library, builtin_library, library_folders, load_knowledge
from plugnproduce.knowledge.devicecache import device_reader
from plugnproduce.lazy import lazy_module
from plugnproduce.resources import descriptions_path

if TYPE_CHECKING:  # the concepts are imported by the use cases that need them
    from plugnproduce import reasoning
    from plugnproduce.ontology.taxonomy import Taxonomy
    from plugnproduce.reasoning.repairs.impact import Impact
    from plugnproduce.validation import Report
else:
    reasoning = lazy_module("plugnproduce.reasoning")  # a validation needs no reasoner


@lru_cache(maxsize=8)
def _loaded(libraries: tuple[Library, ...]) -> Knowledge:
    from plugnproduce.knowledge.cache import cached_knowledge

    return cached_knowledge(libraries, lambda: load_knowledge(libraries))


def knowledge(libraries: tuple[str | Path, ...] = (), builtin: bool = True) -> Knowledge:
    """Load the knowledge of the built-in library (unless ``builtin`` is false) and ``libraries``.

    Loading the same libraries again returns the same object, and a later process reads it back from the user's
    cache folder while the files are unchanged (:mod:`plugnproduce.knowledge.cache`); every use case takes the
    result as its ``knowledge`` argument (default: the built-in library alone).
    """
    libs = ((builtin_library(),) if builtin else ()) + library_folders(libraries)
    return _loaded(libs)


def knowledge_for_cell(path: str | Path, base: Knowledge | None = None) -> Knowledge:
    """``base`` (default: built-in) with the libraries a cell file lists under ``libraries:`` (read back from the
    cache folder as :func:`knowledge` is, unless ``base`` tries TBox files out)."""
    base = base or knowledge()
    extra = tuple(lib for lib in library_folders(kept_cell_libraries(path)) if lib not in base.libraries)
    if not extra:
        return base
    if base.extra_tbox or base.left_out:
        return base.with_libraries(extra)
    return _loaded(base.libraries + extra)


def _read_cell(path: str | Path, k: Knowledge) -> Cell:
    """A cell file with its devices, the file and each device read back from the cache folder while unchanged."""
    return load_cell(path, k.taxonomy, k.device, device_reader(k.taxonomy), kept_cell_device_files)


def _k(k: Knowledge | None) -> Knowledge:
    return k if k is not None else knowledge()


def validate(paths: list[str | Path], knowledge: Knowledge | None = None,
             progress: Callable[[str], None] | None = None) -> Report:
    """Validate description files and folders; ``progress`` is told each phase as it begins."""
    from plugnproduce.validation import validate_paths

    return validate_paths(paths, _k(knowledge), progress=progress)


def validate_tasks(tasks: list[Task], knowledge: Knowledge | None = None) -> Report:
    """Validate tasks already read (e.g. from an editor's YAML) as :func:`validate` validates task files."""
    from plugnproduce.validation import validate_tasks as validate_read

    return validate_read(tasks, _k(knowledge))


def cell(path: str | Path, knowledge: Knowledge | None = None) -> Cell:
    """Read a cell file (with the libraries it lists, added to ``knowledge``)."""
    return _read_cell(path, knowledge_for_cell(path, knowledge))


def catalogue(folder: str | Path | None = None, knowledge: Knowledge | None = None) -> list[DeviceDescription]:
    """Read a catalogue of device descriptions (default: every device of the loaded libraries)."""
    k = _k(knowledge)
    if folder is None:
        return list(k.devices)
    from plugnproduce.description.loader import load_devices  # a catalogue of thousands is read, not kept

    return load_devices(folder, k.taxonomy)


def _load_task(path: Path) -> Task:
    from plugnproduce.description.taskfile import load_task  # YAML: only for a task file not kept

    return load_task(path)


def task(path: str | Path) -> Task:
    """Read a task file (as read before while the file is unchanged, :func:`plugnproduce.folders.kept`)."""
    return kept("task", Path(path), _load_task, lambda value: isinstance(value, Task))


def task_from_text(data: bytes | str, name: str) -> Task:
    """Read a task description from YAML text (an upload, an editor's buffer); ``name`` names it in messages."""
    from plugnproduce.description.taskfile import parse_task

    return parse_task(data.encode("utf-8") if isinstance(data, str) else data, name)


def task_text(the_task: Task, block: bool = False) -> str:
    """A task as a YAML task file (``block``: every value on a line of its own)."""
    from plugnproduce import collector
    from plugnproduce.description.taskfile import task_to_yaml

    with collector.paused():  # its only garbage is acyclic temporaries: a long task's text pays for no collection
        return task_to_yaml(the_task, block)


def builtin(*parts: str) -> Path:
    """A path inside the built-in descriptions, e.g. ``builtin("cells", "bin-picking.yaml")``."""
    return descriptions_path().joinpath(*parts)



class DeviceView(TypedDict):
    """A device as every face shows it (``pnp discover --json``, the HTTP API, the page)."""

    id: str
    label: str
    classes: list[str]
    """The labels of its classes in the taxonomy."""
    skills: list[str]
    """The labels of its skills."""
    protocol: str
    endpoint: str


def device_view(device: DeviceDescription, taxonomy: Taxonomy) -> DeviceView:
    """The one JSON view of a device both faces give: id, label, classes, skills, protocol, endpoint."""
    return {"id": device.id, "label": device.label,
            "classes": [taxonomy.label(c) for c in device.classes],
            "skills": [taxonomy.label(s) for s in device.skills],
            "protocol": device.protocol, "endpoint": device.endpoint}


CellArg = Cell | str | Path
TaskArg = Task | str | Path


def cell_and_knowledge(cell_or_path: CellArg, knowledge: Knowledge | None) -> tuple[Cell, Knowledge]:
    """The cell and the knowledge to reason with: ``knowledge`` plus the cell file's libraries."""
    if isinstance(cell_or_path, Cell):
        if cell_or_path.file and Path(cell_or_path.file).is_file():
            return cell_or_path, knowledge_for_cell(cell_or_path.file, knowledge)
        return cell_or_path, _k(knowledge)
    k = knowledge_for_cell(cell_or_path, knowledge)
    return _read_cell(cell_or_path, k), k


def as_task(task_or_path: TaskArg) -> Task:
    return task_or_path if isinstance(task_or_path, Task) else task(task_or_path)


def _devices(catalogue_or_folder: list[DeviceDescription] | str | Path | None, k: Knowledge) -> list[DeviceDescription]:
    if isinstance(catalogue_or_folder, list):
        return catalogue_or_folder
    return catalogue(catalogue_or_folder, k)


def impact(extensions: list[Path], cell_files: list[Path] | None = None,
           knowledge: Knowledge | None = None) -> Impact:
    """What adding the TBox files ``extensions`` to ``knowledge`` changes: offered commands per cell
    (default: every cell of the loaded libraries), catalogue roles, the libraries' tasks, and the
    validation findings (shapes, structure) of every catalogue device and cell, before and after."""
    from plugnproduce.reasoning.repairs.impact import impact as compute

    return compute(_k(knowledge), extensions, cell_files, _findings)


def _findings(k: Knowledge, files: Sequence[Path]) -> set[tuple[str, int, str]]:
    """What validating ``files`` against ``k`` finds, as (file, line, message)."""
    from plugnproduce.validation import validate_paths

    return {(p.file, p.line, p.message) for p in validate_paths(list(files), k).problems}


def export_ontology(fmt: str = "rdfxml", inferred: bool = False, knowledge: Knowledge | None = None) -> bytes:
    """The merged TBox of ``knowledge`` as one ontology in ``fmt`` (``rdfxml``, ``turtle``, ``owlxml``); with
    ``inferred``, the hierarchy HermiT derived as asserted axioms annotated ``pnp:inferredBy "HermiT"``."""
    from plugnproduce.ontology.export import merged_tbox, serialise

    k = _k(knowledge)
    sources = [lib.name for lib in k.libraries] or ["the pnp ontology"]
    return serialise(merged_tbox(k.tbox(), k.taxonomy, sources, inferred), fmt)
