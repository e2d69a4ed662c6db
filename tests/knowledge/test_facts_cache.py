"""What the reasoner is told about a device (its ASP facts: skills, chart, where each role's region leaves it) is
kept in the user's cache folder beside the device, under the keys of the device as read and of the knowledge it
was made with; an edit of the device's chart, of a process or of the taxonomy is seen by the next command, which
answers as a command with nothing kept does. On a user library outside the package."""

from __future__ import annotations

import gc
import os
import shutil
import subprocess
import sys
import weakref
from dataclasses import replace
from pathlib import Path

import pytest

import plugnproduce
from plugnproduce.description.loader import load_device
from plugnproduce.knowledge import Knowledge, builtin_library, library_folders, load_knowledge
from plugnproduce.knowledge.cache import cached_knowledge, kept_for
from plugnproduce.knowledge.devicecache import cached_device, kept_facts

GLUE = Path(__file__).resolve().parents[1] / "data" / "libraries" / "glue-dispensing"
SRC = str(Path(plugnproduce.__file__).resolve().parents[1])


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    return Path(shutil.copytree(GLUE, tmp_path / "glue-dispensing"))


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")


def _capabilities(home: Path, cell: Path) -> str:
    """``pnp capabilities --cell CELL``'s output with ``home`` as the user's home (its cache folder within)."""
    env = {**os.environ, "HOME": str(home), "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get(
        "PYTHONPATH"))))}
    env.pop("XDG_CACHE_HOME", None)
    done = subprocess.run([sys.executable, "-m", "plugnproduce", "capabilities", "--cell", str(cell)], env=env,
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout


def _kept_facts(home: Path) -> list[str]:
    return sorted(p.name for p in (home / ".cache" / "plugnproduce").glob("facts-*.pickle"))


def test_capabilities_read_the_kept_facts_and_see_every_edit_as_a_cold_command_does(library: Path,
                                                                                  tmp_path: Path) -> None:
    cell, home = library / "cells" / "glue-cell.yaml", tmp_path / "home"
    first = _capabilities(home, cell)
    assert "lay-bead         dispenser=dispenser" in first
    kept = _kept_facts(home)
    assert kept  # the built-in processes and the library's lay-bead, for the dispenser
    assert _capabilities(home, cell) == first and _kept_facts(home) == kept
    # the process no longer hands the bead's length to the dispenser's request: the device is unchanged, the
    # knowledge is not
    _edit(library / "processes" / "lay-bead.scxml", 'pnp:params="length glue"', 'pnp:params="glue"')
    edited = _capabilities(home, cell)
    assert "its request Dispense needs the argument bead length" in edited
    assert edited == _capabilities(tmp_path / "cold-process", cell)
    # the device's chart no longer lays a bead: dispensing goes back to ready
    _edit(library / "devices" / "dispenser.scxml", 'event="bead.done" target="laid"', 'event="bead.done" target="ready"')
    _edit(library / "processes" / "lay-bead.scxml", 'pnp:params="glue"', 'pnp:params="length glue"')
    edited = _capabilities(home, cell)
    assert "lay-bead         dispenser=dispenser" not in edited and "lay-bead\n" in edited
    assert edited == _capabilities(tmp_path / "cold-chart", cell)
    # the taxonomy makes a glue dispenser a device that can grip, too
    _edit(library / "ontology" / "glue.ttl", "owl:someValuesFrom gl:CanDispense ] .",
          "owl:someValuesFrom gl:CanDispense ] , [ a owl:Restriction ; owl:onProperty pnp:hasSkill ; "
          "owl:someValuesFrom pnp:CanGrip ] .")
    edited = _capabilities(home, cell)
    assert "role 'gripper' of close-gripper needs a device that can grip; no device" not in edited
    assert edited == _capabilities(tmp_path / "cold-taxonomy", cell)


def _knowledge(library: Path, folder: Path) -> Knowledge:
    libraries = (builtin_library(), *library_folders([library]))
    return cached_knowledge(libraries, lambda: load_knowledge(libraries), folder)


def test_knowledge_read_through_the_cache_carries_its_key_and_a_copy_does_not(library: Path,
                                                                             tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first, again = _knowledge(library, cache), _knowledge(library, cache)
    assert first.key is not None and again.key == first.key and again is not first
    assert load_knowledge(first.libraries).key is None
    assert replace(first, processes=()).key is None  # other processes under the same key would be served stale
    _edit(library / "processes" / "lay-bead.ttl", '"lay a glue bead"', '"lay a thin bead"')
    assert _knowledge(library, cache).key not in (None, first.key)


def test_a_chart_outside_the_libraries_is_part_of_the_knowledge_key(library: Path, tmp_path: Path) -> None:
    outside = tmp_path / "charts" / "lay-bead.scxml"
    outside.parent.mkdir()
    shutil.move(library / "processes" / "lay-bead.scxml", outside)
    _edit(library / "processes" / "lay-bead.ttl", "<lay-bead.scxml>", f"<{outside.as_uri()}>")
    cache = tmp_path / "cache"
    first = _knowledge(library, cache)
    _edit(outside, 'pnp:params="length glue"', 'pnp:params="glue"')
    again = _knowledge(library, cache)
    assert again.process("lay-bead") != first.process("lay-bead")
    assert again.key not in (None, first.key)


class Makes:
    """Device facts made, counting the times they are really made."""

    def __init__(self, text: str = "device(\"dispenser\").\n") -> None:
        self.text, self.count = text, 0

    def __call__(self) -> str:
        self.count += 1
        return self.text


def test_facts_are_kept_only_for_a_device_the_cache_gave_and_knowledge_with_a_key(library: Path,
                                                                                  tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    k = _knowledge(library, cache)
    ttl = library / "devices" / "dispenser.ttl"
    device, makes = cached_device(ttl, k.taxonomy, cache), Makes()
    assert kept_facts(device, k.key, makes) == makes.text
    assert kept_facts(device, k.key, makes) == makes.text and makes.count == 1
    assert len(list(cache.glob("facts-*.pickle"))) == 1
    assert kept_facts(device, "another knowledge", makes) == makes.text and makes.count == 2
    assert kept_facts(device, None, makes) == makes.text and makes.count == 3
    same = load_device(ttl, k.taxonomy)  # equal, but not read through the cache: what it was read from is unknown
    assert same == device
    assert kept_facts(same, k.key, makes) == makes.text and makes.count == 4
    assert kept_facts(replace(device, label="another"), k.key, makes) == makes.text and makes.count == 5


def test_a_damaged_kept_facts_file_is_made_again(library: Path, tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    k = _knowledge(library, cache)
    device, makes = cached_device(library / "devices" / "dispenser.ttl", k.taxonomy, cache), Makes()
    kept_facts(device, k.key, makes)
    (kept,) = cache.glob("facts-*.pickle")
    kept.write_bytes(b"not a pickle")
    assert kept_facts(device, k.key, makes) == makes.text and makes.count == 2
    assert kept_facts(device, k.key, makes) == makes.text and makes.count == 2


def test_what_is_made_of_the_knowledge_alone_is_kept_under_its_key_in_its_cache_folder(library: Path,
                                                                                      tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    k, makes = _knowledge(library, cache), Makes("process(\"lay-bead\").\n")
    assert kept_for(k, "processes", makes) == makes.text
    assert kept_for(_knowledge(library, cache), "processes", makes) == makes.text and makes.count == 1
    assert len(list(cache.glob("made-*.pickle"))) == 1
    assert kept_for(k, "something else", makes) == makes.text and makes.count == 2
    unkeyed = load_knowledge(k.libraries)
    assert kept_for(unkeyed, "processes", makes) == makes.text and makes.count == 3
    _edit(library / "processes" / "lay-bead.ttl", '"lay a glue bead"', '"lay a thin bead"')
    assert kept_for(_knowledge(library, cache), "processes", makes) == makes.text and makes.count == 4


def test_a_device_the_cache_gave_is_not_held_once_dropped(library: Path, tmp_path: Path) -> None:
    """A long-running process (the HMI's server) reads a cell's devices for every request: what names them for
    their facts must not keep them alive."""
    cache = tmp_path / "cache"
    k = _knowledge(library, cache)
    device = cached_device(library / "devices" / "dispenser.ttl", k.taxonomy, cache)
    kept_facts(device, k.key, Makes())
    gone = weakref.ref(device)
    del device
    gc.collect()
    assert gone() is None
