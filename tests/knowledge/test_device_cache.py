"""A device description read once is kept in the user's cache folder and read back while it, its device state chart
and the taxonomy are unchanged; any edit is seen by the next command, a damaged kept file is read again silently,
and a cache folder that cannot be written costs only the reading. On a user library outside the package."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import plugnproduce
from plugnproduce.description.loader import load_device
from plugnproduce.description.model import DeviceDescription
from plugnproduce.knowledge import builtin_library, library_folders, load_knowledge
from plugnproduce.knowledge.devicecache import cached_device, kept_devices
from plugnproduce.ontology.taxonomy import Taxonomy

GLUE = Path(__file__).resolve().parents[1] / "data" / "libraries" / "glue-dispensing"
SRC = str(Path(plugnproduce.__file__).resolve().parents[1])


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    return Path(shutil.copytree(GLUE, tmp_path / "glue-dispensing"))


class Reads:
    """``load_device``, counting the times it really reads a description."""

    def __init__(self) -> None:
        self.count = 0

    def __call__(self, path: Path, taxonomy: Taxonomy) -> DeviceDescription:
        self.count += 1
        return load_device(path, taxonomy)


def _taxonomy(library: Path) -> Taxonomy:
    return load_knowledge((builtin_library(), *library_folders([library]))).taxonomy


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")


def test_an_unchanged_device_is_read_once_and_read_back_equal(library: Path, tmp_path: Path) -> None:
    reads, cache, ttl = Reads(), tmp_path / "cache", library / "devices" / "dispenser.ttl"
    taxonomy = _taxonomy(library)
    first = cached_device(ttl, taxonomy, cache, reads)
    again = cached_device(ttl, taxonomy, cache, reads)
    assert reads.count == 1 and len(list(kept_devices(cache))) == 1
    assert again is not first and again == first and again.chart == first.chart
    assert (again.label, again.skills) == ("Glue dispenser GD-1", ("http://example.org/glue#CanDispense",))


def test_an_edited_description_is_read_again(library: Path, tmp_path: Path) -> None:
    reads, cache, ttl = Reads(), tmp_path / "cache", library / "devices" / "dispenser.ttl"
    taxonomy = _taxonomy(library)
    cached_device(ttl, taxonomy, cache, reads)
    _edit(ttl, '"Glue dispenser GD-1"', '"Glue dispenser GD-2"')
    assert cached_device(ttl, taxonomy, cache, reads).label == "Glue dispenser GD-2"
    assert reads.count == 2


def test_an_edited_device_state_chart_is_read_again(library: Path, tmp_path: Path) -> None:
    reads, cache, ttl = Reads(), tmp_path / "cache", library / "devices" / "dispenser.ttl"
    taxonomy = _taxonomy(library)
    cached_device(ttl, taxonomy, cache, reads)
    _edit(library / "devices" / "dispenser.scxml", "upnp.event.bead_laid", "upnp.event.bead_done")
    device = cached_device(ttl, taxonomy, cache, reads)
    assert reads.count == 2
    assert [c.name for t in device.transitions for c in t.sends] == ["bead_done"]


def test_a_device_reasoned_with_another_taxonomy_is_read_again(library: Path, tmp_path: Path) -> None:
    reads, cache, ttl = Reads(), tmp_path / "cache", library / "devices" / "dispenser.ttl"
    cached_device(ttl, _taxonomy(library), cache, reads)
    # the library's ontology makes the dispenser's class imply a second skill
    _edit(library / "ontology" / "glue.ttl", "owl:someValuesFrom gl:CanDispense ] .",
          "owl:someValuesFrom gl:CanDispense ] , [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; "
          "owl:someValuesFrom pnp:CanGrip ] .")
    device = cached_device(ttl, _taxonomy(library), cache, reads)
    assert reads.count == 2 and "http://plugnproduce.org/ontology#CanGrip" in device.skills


def test_a_damaged_kept_file_is_read_again_and_kept_anew(library: Path, tmp_path: Path) -> None:
    reads, cache, ttl = Reads(), tmp_path / "cache", library / "devices" / "dispenser.ttl"
    taxonomy = _taxonomy(library)
    first = cached_device(ttl, taxonomy, cache, reads)
    (kept,) = kept_devices(cache)
    kept.write_bytes(b"not a pickle")
    assert cached_device(ttl, taxonomy, cache, reads) == first
    assert cached_device(ttl, taxonomy, cache, reads) == first
    assert reads.count == 2


def test_a_cache_folder_that_cannot_be_made_still_answers(library: Path, tmp_path: Path) -> None:
    reads, ttl = Reads(), library / "devices" / "dispenser.ttl"
    (tmp_path / "a-file").write_text("", encoding="utf-8")
    cache = tmp_path / "a-file" / "cache"  # no folder can be made under a file
    taxonomy = _taxonomy(library)
    assert cached_device(ttl, taxonomy, cache, reads).label == "Glue dispenser GD-1"
    assert cached_device(ttl, taxonomy, cache, reads).label == "Glue dispenser GD-1"
    assert reads.count == 2


def _pnp(home: Path, *args: str, read_only: Path | None = None) -> str:
    """``pnp ARGS``'s output with ``home`` as the user's home; with ``read_only``, that folder mounted read-only
    (for root, whom file modes do not stop) or made read-only."""
    env = {**os.environ, "HOME": str(home), "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get(
        "PYTHONPATH"))))}
    env.pop("XDG_CACHE_HOME", None)
    command = [sys.executable, "-m", "plugnproduce", *args]
    if read_only is not None and os.geteuid() == 0:
        folder = str(read_only)
        command = ["unshare", "-m", "sh", "-c", 'mount --bind "$0" "$0" && mount -o remount,bind,ro "$0" && exec "$@"',
                   folder, *command]
    elif read_only is not None:
        read_only.chmod(0o555)
    try:
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300, check=False)
    finally:
        if read_only is not None:
            read_only.chmod(0o755)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.skipif(os.geteuid() == 0 and shutil.which("unshare") is None, reason="root needs unshare -m")
def test_a_read_only_cache_folder_answers_from_what_it_keeps_and_sees_an_edit(library: Path, tmp_path: Path) -> None:
    cell = library / "cells" / "by-file.yaml"
    cell.write_text("cell: by-file\nlibraries:\n  - ..\ndevices:\n  - ../devices/dispenser.ttl\n", encoding="utf-8")
    first = _pnp(tmp_path, "capabilities", "--cell", str(cell))
    assert "lay-bead         dispenser=dispenser" in first
    cache = tmp_path / ".cache" / "plugnproduce"
    kept = sorted(p.name for p in cache.iterdir())
    assert any(n.startswith("device-") for n in kept) and any(n.startswith("knowledge-") for n in kept)
    assert _pnp(tmp_path, "capabilities", "--cell", str(cell), read_only=cache) == first
    _edit(library / "devices" / "dispenser.ttl", "dev:dispenser", "dev:gluer")
    edited = _pnp(tmp_path, "capabilities", "--cell", str(cell), read_only=cache)
    assert "lay-bead         dispenser=gluer" in edited
    assert sorted(p.name for p in cache.iterdir()) == kept  # nothing could be kept
