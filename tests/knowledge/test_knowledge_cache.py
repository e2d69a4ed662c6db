"""The loaded knowledge is kept in the user's cache folder and read back while its files are unchanged; a change
to any file of a library (or to a chart a process names outside it) is seen by the next command."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from plugnproduce.knowledge import Knowledge, builtin_library, library_folders, load_knowledge
from plugnproduce.knowledge.cache import cached_knowledge, kept_files

GLUE = Path(__file__).resolve().parents[1] / "data" / "libraries" / "glue-dispensing"


@pytest.fixture()
def library(tmp_path: Path) -> Path:
    return Path(shutil.copytree(GLUE, tmp_path / "glue-dispensing"))


class Loads:
    """``load_knowledge`` of some libraries, counting the times it really loads."""

    def __init__(self, root: Path) -> None:
        self.libraries = (builtin_library(), *library_folders([root]))
        self.count = 0

    def __call__(self) -> Knowledge:
        self.count += 1
        return load_knowledge(self.libraries)


def test_the_second_load_of_unchanged_libraries_reads_what_was_kept(library: Path, tmp_path: Path) -> None:
    loads, cache = Loads(library), tmp_path / "cache"
    first = cached_knowledge(loads.libraries, loads, cache)
    again = cached_knowledge(loads.libraries, loads, cache)
    assert loads.count == 1 and len(list(kept_files(cache))) == 1
    assert again is not first and again.process("lay-bead") == first.process("lay-bead")
    assert [p.id for p in again.processes] == [p.id for p in first.processes]
    assert again.taxonomy.to_json() == first.taxonomy.to_json()


def test_an_edited_process_description_is_loaded_again(library: Path, tmp_path: Path) -> None:
    loads, cache = Loads(library), tmp_path / "cache"
    assert cached_knowledge(loads.libraries, loads, cache).process("lay-bead").label == "lay a glue bead"
    ttl = library / "processes" / "lay-bead.ttl"
    ttl.write_text(ttl.read_text(encoding="utf-8").replace('"lay a glue bead"', '"lay a thin bead"'),
                   encoding="utf-8")
    assert cached_knowledge(loads.libraries, loads, cache).process("lay-bead").label == "lay a thin bead"
    assert loads.count == 2


def test_a_chart_outside_the_library_is_checked_when_read_back(library: Path, tmp_path: Path) -> None:
    outside = tmp_path / "charts" / "lay-bead.scxml"
    outside.parent.mkdir()
    shutil.move(library / "processes" / "lay-bead.scxml", outside)
    ttl = library / "processes" / "lay-bead.ttl"
    text = ttl.read_text(encoding="utf-8")
    assert "lay-bead.scxml" in text
    ttl.write_text(text.replace("lay-bead.scxml", outside.as_uri()), encoding="utf-8")
    loads, cache = Loads(library), tmp_path / "cache"
    cached_knowledge(loads.libraries, loads, cache)
    cached_knowledge(loads.libraries, loads, cache)
    assert loads.count == 1
    outside.write_text(outside.read_text(encoding="utf-8") + "\n<!-- edited -->\n", encoding="utf-8")
    cached_knowledge(loads.libraries, loads, cache)
    assert loads.count == 2


def test_a_damaged_kept_file_is_loaded_again(library: Path, tmp_path: Path) -> None:
    loads, cache = Loads(library), tmp_path / "cache"
    cached_knowledge(loads.libraries, loads, cache)
    (kept,) = kept_files(cache)
    kept.write_bytes(b"not a pickle")
    assert cached_knowledge(loads.libraries, loads, cache).process("lay-bead").label == "lay a glue bead"
    assert loads.count == 2
