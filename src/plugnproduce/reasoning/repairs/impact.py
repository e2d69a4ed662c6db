"""What a TBox edit does: offered commands, catalogue roles and task plausibility, before and after.

``before`` is the loaded knowledge; ``after`` the same knowledge with the extension files
classified in. For every cell the offered commands and their bindings are compared; for every
catalogue device the process roles it can fill; for every library task in every cell whether
it is plausible.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from plugnproduce.description.loader import cell_libraries, load_cell, load_task
from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import DescriptionError
from plugnproduce.knowledge.libraries import Knowledge, library_folders, load_knowledge
from plugnproduce.reasoning.checks import offers, plausibility

Bindings = dict[str, set[str]]
"""Offered command → its role bindings, each written ``role=device ...``."""

Finding = tuple[str, int, str]
"""A validation finding: file, line (0 for none), message."""

Validator = Callable[[Knowledge, Sequence[Path]], set[Finding]]
"""Validates description files (devices, cells) against a knowledge: shapes, schema and structure."""


@dataclass
class Impact:
    """The changes a TBox edit makes; empty lists when it changes nothing."""

    extensions: list[str]
    cells: list[dict[str, object]] = field(default_factory=list)
    catalogue: list[dict[str, object]] = field(default_factory=list)
    tasks: list[dict[str, object]] = field(default_factory=list)
    new_violations: list[dict[str, object]] = field(default_factory=list)
    """Findings of the validation (shapes, structure) of catalogue devices and cells that the edit brings."""
    cured_violations: list[dict[str, object]] = field(default_factory=list)
    """Findings the edit removes."""

    @property
    def changed(self) -> bool:
        """Whether anything changes."""
        return bool(self.cells or self.catalogue or self.tasks or self.new_violations or self.cured_violations)

    def to_json(self) -> dict[str, object]:
        """A JSON-ready dict."""
        return {"extensions": self.extensions, "changed": self.changed, "cells": self.cells,
                "catalogue": self.catalogue, "tasks": self.tasks, "new_violations": self.new_violations,
                "cured_violations": self.cured_violations}


def impact(before: Knowledge, extensions: Sequence[Path], cell_files: Iterable[Path] | None = None,
           validate: Validator | None = None) -> Impact:
    """The impact of adding ``extensions`` (TBox files) to ``before``, on ``cell_files`` (default: the
    libraries' cells), the catalogue and the libraries' tasks; with ``validate``, also the validation
    findings of every catalogue device and every cell that the edit brings or removes."""
    extensions = [p.resolve() for p in extensions]
    after = load_knowledge(before.libraries, tuple(before.extra_tbox) + tuple(extensions))
    before = load_knowledge(before.libraries, before.extra_tbox, tuple(before.left_out) + tuple(extensions))
    result = Impact([str(p) for p in extensions])
    cells = sorted(set(cell_files)) if cell_files is not None else before.cell_files()
    pairs = [(f, _cell(f, before), _cell(f, after)) for f in cells]
    for f, (c0, k0), (c1, k1) in pairs:
        change = _offer_change(_offers(c0, k0), _offers(c1, k1))
        if change:
            note = {"note": "the cell could not be read before the edit"} if c0 is None else {}
            result.cells.append({"cell": str(f), **note, **change})
    result.catalogue = _catalogue_change(before, after)
    result.tasks = _task_changes(before, pairs)
    if validate is not None:
        result.new_violations, result.cured_violations = _violations(before, after, cells, validate)
    return result


def _violations(before: Knowledge, after: Knowledge, cells: Sequence[Path],
                validate: Validator) -> tuple[list[dict[str, object]], list[dict[str, object]]]:
    """The findings on the catalogue devices and the cells after the edit but not before, and the other way."""
    files = sorted({f for lib in after.libraries for f in lib.files("devices")} | set(cells))
    old, new = validate(before, files), validate(after, files)

    def listed(found: set[Finding]) -> list[dict[str, object]]:
        return [{"file": f, "line": n or None, "message": m} for f, n, m in sorted(found)]

    return listed(new - old), listed(old - new)


def _cell(path: Path, k: Knowledge) -> tuple[Cell | None, Knowledge]:
    try:
        k = k.with_libraries(library_folders(cell_libraries(path)))
        return load_cell(path, k.taxonomy, k.device), k
    except DescriptionError:
        return None, k  # e.g. a device of a class only the extension defines: the cell cannot be read before


def _offers(cell: Cell | None, k: Knowledge) -> Bindings:
    if cell is None:
        return {}
    caps = offers.capabilities(cell, k, all_bindings=True)
    return {o.command: {" ".join(f"{r}={d}" for r, d in sorted(b.items())) for b in o.bindings} for o in caps.offered}


def _offer_change(old: Bindings, new: Bindings) -> dict[str, object]:
    added = sorted(set(new) - set(old))
    removed = sorted(set(old) - set(new))
    changed = [{"command": c, "added": sorted(new[c] - old[c]), "removed": sorted(old[c] - new[c])}
               for c in sorted(set(old) & set(new)) if old[c] != new[c]]
    if not (added or removed or changed):
        return {}
    return {"added": [{"command": c, "bindings": sorted(new[c])} for c in added],
            "removed": [{"command": c, "bindings": sorted(old[c])} for c in removed], "changed": changed}


def _roles(device: DeviceDescription, k: Knowledge) -> set[str]:
    skills = k.taxonomy.device_skills(device.classes, device.declared_skills)
    return {f"{p.id}.{r.name}" for p in k.processes for r in p.roles if r.required_skill in skills}


def _catalogue_change(before: Knowledge, after: Knowledge) -> list[dict[str, object]]:
    out: list[dict[str, object]] = []
    for d in after.devices:  # read with the extension: a device of a class only it defines is read too
        old, new = _roles(d, before), _roles(d, after)
        if old != new:
            out.append({"device": d.id, "file": d.where.file, "roles_added": sorted(new - old),
                        "roles_removed": sorted(old - new)})
    return out


def _task_changes(before: Knowledge, pairs: list[tuple[Path, tuple[Cell | None, Knowledge],
                                                       tuple[Cell | None, Knowledge]]]) -> list[dict[str, object]]:
    out: list[dict[str, object]] = []
    for task_file in before.task_files():
        task = load_task(task_file)
        for f, (c0, k0), (c1, k1) in pairs:
            was = c0 is not None and plausibility.check(task, c0, k0).plausible
            now = c1 is not None and plausibility.check(task, c1, k1).plausible
            if was != now:
                out.append({"task": str(task_file), "cell": str(f), "plausible_before": was, "plausible_after": now})
    return out
