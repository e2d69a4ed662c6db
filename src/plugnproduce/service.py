"""The use cases behind every interface (CLI, HTTP API, notebooks).

Functions here load descriptions, call the concepts (validation, reasoning, code
generation, execution) and return typed results; they never print.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from plugnproduce.description.loader import load_cell, load_devices, load_processes, load_task
from plugnproduce.description.model import Cell, DeviceDescription, ProcessDescription, Task
from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy
from plugnproduce.resources import descriptions_path
from plugnproduce.validation import Report, validate_paths


@dataclass(frozen=True)
class Knowledge:
    """What every use case needs: the taxonomy closure and the known processes."""

    taxonomy: Taxonomy
    processes: tuple[ProcessDescription, ...]

    def process(self, command: str) -> ProcessDescription:
        """The process a command names."""
        for p in self.processes:
            if p.id == command:
                return p
        raise KeyError(command)


@lru_cache(maxsize=8)
def knowledge(processes_dir: Path | None = None) -> Knowledge:
    """The taxonomy (cached by content) and the processes of ``processes_dir`` (default: built-in)."""
    taxonomy = load_taxonomy()
    folder = processes_dir or descriptions_path() / "processes"
    return Knowledge(taxonomy, tuple(load_processes(folder)))


def validate(paths: list[str | Path]) -> Report:
    """Validate description files and folders."""
    return validate_paths(paths, knowledge().taxonomy)


def cell(path: str | Path) -> Cell:
    """Read a cell file."""
    return load_cell(path, knowledge().taxonomy)


def catalogue(folder: str | Path | None = None) -> list[DeviceDescription]:
    """Read a catalogue of device descriptions (default: the built-in devices)."""
    return load_devices(folder or descriptions_path() / "devices", knowledge().taxonomy)


def task(path: str | Path) -> Task:
    """Read a task file."""
    return load_task(path)


def builtin(*parts: str) -> Path:
    """A path inside the built-in descriptions, e.g. ``builtin("cells", "bin-picking.yaml")``."""
    return descriptions_path().joinpath(*parts)
