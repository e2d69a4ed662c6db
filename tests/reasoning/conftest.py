"""Fixtures for the reasoner: the bin-picking cell, the catalogue, the built-in tasks, and an ASP runner."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import clingo
import pytest

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.description.model import Cell, DeviceDescription, Task
from plugnproduce.resources import rules_path
from tests.conftest import edit

DESCRIPTIONS = service.builtin()
BIN_PICKING = DESCRIPTIONS / "cells" / "bin-picking.yaml"
TASKS = DESCRIPTIONS / "tasks"


@pytest.fixture(scope="session")
def cell() -> Cell:
    return service.cell(BIN_PICKING)


@pytest.fixture(scope="session")
def devices() -> list[DeviceDescription]:
    return service.catalogue()


@pytest.fixture(scope="session")
def device(devices: list[DeviceDescription]):
    def get(name: str) -> DeviceDescription:
        return next(d for d in devices if d.id == name)

    return get


@pytest.fixture()
def vacuum_with_default(device_copy, taxonomy) -> DeviceDescription:
    """The vacuum gripper, made to declare a default vacuum: it needs no process to supply one."""
    ttl, _ = device_copy("vacuum-gripper")
    edit(ttl, "pnp:minValue 20 ; pnp:maxValue 85 .", "pnp:minValue 20 ; pnp:maxValue 85 ; pnp:defaultValue 60 .")
    return load_device(ttl, taxonomy)


def task(name: str) -> Task:
    return service.task(TASKS / f"{name}.yaml")


def answer_sets(files: Sequence[str], facts: str, show: Sequence[str] = (), arguments: Sequence[str] = ()) -> list[set[str]]:
    """Every (optimal, with --opt-mode=optN) answer set of rules/FILES + FACTS, restricted to the SHOW predicates."""
    ctl = clingo.Control(["--warn=none", "0", *arguments])
    for f in files:
        ctl.load(str(rules_path() / f))
    ctl.add("base", [], facts)
    ctl.add("base", [], "".join(f"#show {p}." for p in show))
    ctl.ground([("base", [])])
    models: list[tuple[bool, set[str]]] = []
    ctl.solve(on_model=lambda m: models.append((m.optimality_proven, {str(s) for s in m.symbols(shown=True)})))
    if "--opt-mode=optN" in arguments:
        return [m for proven, m in models if proven]
    return [m for _, m in models]


def write(tmp: Path, name: str, text: str) -> Path:
    p = tmp / name
    p.write_text(text)
    return p
