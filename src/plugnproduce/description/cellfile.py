"""Cell files (YAML): the cell's name, the device descriptions and libraries it lists, and the cell read with its
devices (named in :mod:`plugnproduce.description.loader` too).

Nothing here reads Turtle: a cell's devices are read by the reader it is given (the knowledge's, which keeps them
in the cache folder), so a command over a cell seen before needs no RDF parser.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.folders import kept

if TYPE_CHECKING:  # YAML is read when a cell file is not kept in the cache folder
    import yaml

    from plugnproduce.ontology.taxonomy import Taxonomy


def _load_device(path: Path, taxonomy: Taxonomy) -> DeviceDescription:
    from plugnproduce.description.loader import load_device  # reads RDF

    return load_device(path, taxonomy)


def _files(value: object) -> bool:
    return (isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], str)
            and isinstance(value[1], list) and all(isinstance(f, Path) and isinstance(n, int) for f, n in value[1]))


def _folders(value: object) -> bool:
    return isinstance(value, list) and all(isinstance(f, Path) for f in value)


def kept_cell_device_files(path: str | Path) -> tuple[str, list[tuple[Path, int]]]:
    """:func:`cell_device_files`, as read before while the file is unchanged (:func:`~plugnproduce.folders.kept`)."""
    return kept("cellfiles", Path(path), _device_files, _files)


def kept_cell_libraries(path: str | Path) -> list[Path]:
    """:func:`cell_libraries`, as read before while the file is unchanged and each folder is there."""
    folders = kept("celllibraries", Path(path), _libraries, _folders)
    return folders if all(f.is_dir() for f in folders) else _libraries(Path(path))


def cell_device_files(path: str | Path) -> tuple[str, list[tuple[Path, int]]]:
    """A cell file's name and its device description files with the lines that list them."""
    return _device_files(Path(path))


def cell_libraries(path: str | Path) -> list[Path]:
    """The library folders a cell file lists under ``libraries:`` (relative to the cell file)."""
    return _libraries(Path(path))


def _device_files(p: Path) -> tuple[str, list[tuple[Path, int]]]:
    import yaml

    from plugnproduce.description.taskfile import _mapping, _plain, _unknown_keys
    from plugnproduce.safeio import parse_yaml_node

    top = _mapping(parse_yaml_node(p), p, "cell")
    _unknown_keys(top, {"cell", "devices", "libraries"}, p, "cell")
    if "cell" not in top or "devices" not in top or not isinstance(top["devices"], yaml.SequenceNode):
        raise DescriptionError("a cell needs 'cell' (its name) and 'devices' (a list of files)", p, 1)
    files = []
    for node in top["devices"].value:
        if not isinstance(node, yaml.ScalarNode):
            raise DescriptionError("each device is a path to a device description", p, node.start_mark.line + 1)
        files.append((_device_path(p, node), node.start_mark.line + 1))
    return str(_plain(top["cell"])), files


def _libraries(p: Path) -> list[Path]:
    import yaml

    from plugnproduce.description.taskfile import _mapping
    from plugnproduce.safeio import parse_yaml_node

    top = _mapping(parse_yaml_node(p), p, "cell")
    node = top.get("libraries")
    if node is None:
        return []
    if not isinstance(node, yaml.SequenceNode) or not all(isinstance(n, yaml.ScalarNode) for n in node.value):
        raise DescriptionError("libraries must be a list of folders (relative to the cell file)", p,
                               node.start_mark.line + 1)
    out = []
    for n in node.value:
        folder = (p.parent / n.value).resolve()
        if not folder.is_dir():
            raise DescriptionError(f"library folder {excerpt(n.value)} not found", p, n.start_mark.line + 1)
        out.append(folder)
    return out


MAX_PATH = 1024
"""Longest device path a cell may list (file systems refuse names much longer than 255 bytes anyway)."""


def _device_path(cell: Path, node: yaml.ScalarNode) -> Path:
    """A device path a cell lists, resolved beside the cell; one no file system could hold is refused."""
    value = str(node.value)
    parts = value.replace("\\", "/").split("/")
    if "\0" in value or len(value) > MAX_PATH or any(len(part.encode("utf-8", "replace")) > 255 for part in parts):
        raise DescriptionError(f"device path {excerpt(value)!r} ({len(value)} characters) cannot name a file; "
                               "expected a path to a device description", cell, node.start_mark.line + 1)
    return (cell.parent / value).resolve()


def not_a_description(entry: Path) -> str | None:
    """Why a file a cell lists is no device description (a device description is a Turtle ``.ttl`` file), or None.

    Nothing of the file is read, so nothing of it (``/etc/passwd``) is ever quoted.
    """
    if entry.suffix.lower() == ".ttl" or not entry.is_file():
        return None
    return (f"device entry {excerpt(entry.name)!r} is a file that is no device description; expected a "
            "Turtle file (.ttl) or the id of a device of a loaded library")


def load_cell(path: str | Path, taxonomy: Taxonomy,
              by_id: Callable[[str], DeviceDescription | None] | None = None,
              read: Callable[[Path], DeviceDescription] | None = None,
              entries: Callable[[Path], tuple[str, list[tuple[Path, int]]]] = cell_device_files) -> Cell:
    """Read a cell (YAML) and all its device descriptions (its entries by ``entries``, e.g.
    :func:`kept_cell_device_files`; each device by ``read``, default
    :func:`~plugnproduce.description.loader.load_device` with ``taxonomy``).

    An entry that is no file but a plain id (``robot``) names a catalogue device, found by ``by_id``.
    """
    name, files = entries(Path(path))
    devices = []
    for f, line in files:
        if (why := not_a_description(f)) is not None:
            raise DescriptionError(why, path, line)
        if f.is_file():
            devices.append(read(f) if read is not None else _load_device(f, taxonomy))
            continue
        known = by_id(f.name) if by_id is not None and f.suffix != ".ttl" else None
        if known is None:
            raise DescriptionError(f"device description {excerpt(f.name)} not found; expected a device description "
                                   "file (relative to the cell file) or the id of a device of a loaded library",
                                   path, line)
        devices.append(known)
    ids = [d.id for d in devices]
    for d in devices:
        if ids.count(d.id) > 1:
            raise DescriptionError(f"device id {excerpt(d.id)!r} appears twice in the cell", path)
    return Cell(name, tuple(devices), str(path))
