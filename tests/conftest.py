"""Shared fixtures: the built-in descriptions and the taxonomy closure."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest

from plugnproduce.ontology.taxonomy import Taxonomy, load_taxonomy
from plugnproduce.resources import descriptions_path
from tests.processes import ours, running_descendants

DESCRIPTIONS = descriptions_path()


def pytest_configure(config: pytest.Config) -> None:
    """The tests stop the ``pnp`` processes they start with Ctrl-C (SIGINT), as a user would. A suite started in the
    background by a shell (``python -m pytest &``) inherits SIGINT ignored, and an ignored signal stays ignored in
    every process it starts, so none of them would stop: give the suite Python's own handler, which a started
    process does not inherit."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session", autouse=True)
def no_process_outlives_the_suite() -> Iterator[None]:
    """At the end of the session (of each worker), no ``pnp``/``python -m plugnproduce`` process a test started is
    still running: a leaked one is killed, and the session fails naming it."""
    yield
    leaked = [(pid, cmd) for pid, cmd in running_descendants() if ours(cmd)]
    for pid, _ in leaked:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    assert leaked == [], "processes started by the tests outlived them: " + "; ".join(f"{p} {c}" for p, c in leaked)


@pytest.fixture(scope="session")
def taxonomy() -> Taxonomy:
    """The taxonomy closure of the built-in ontology (HermiT once, then cached)."""
    return load_taxonomy()


@pytest.fixture()
def device_copy(tmp_path: Path):
    """Copy a built-in device description (Turtle + chart) into a temporary folder."""

    def copy(name: str) -> tuple[Path, Path]:
        ttl = shutil.copy(DESCRIPTIONS / "devices" / f"{name}.ttl", tmp_path)
        scxml = shutil.copy(DESCRIPTIONS / "devices" / f"{name}.scxml", tmp_path)
        return Path(ttl), Path(scxml)

    return copy


@pytest.fixture()
def process_copy(tmp_path: Path):
    """Copy a built-in process description (Turtle + chart) into a temporary folder."""

    def copy(name: str) -> tuple[Path, Path]:
        ttl = shutil.copy(DESCRIPTIONS / "processes" / f"{name}.ttl", tmp_path)
        scxml = shutil.copy(DESCRIPTIONS / "processes" / f"{name}.scxml", tmp_path)
        return Path(ttl), Path(scxml)

    return copy


def edit(path: Path, old: str, new: str) -> None:
    """Replace text in a file, failing loudly if the text is not there."""
    text = path.read_text()
    assert old in text, f"{old!r} not in {path.name}"
    path.write_text(text.replace(old, new))
