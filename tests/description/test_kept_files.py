"""Task and cell files read once are kept in the user's cache folder and read back, without YAML, while unchanged:
an edit is read anew, bad input is said every time and never kept, a damaged kept file is read again, and a cell
file named relatively is read as the file it names in each working folder. On a user library outside the package."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import plugnproduce.description.taskfile
from plugnproduce import service
from plugnproduce.description.cellfile import kept_cell_device_files as cell_device_files
from plugnproduce.description.cellfile import kept_cell_libraries as cell_libraries
from plugnproduce.description.model import Task
from plugnproduce.errors import DescriptionError

GLUE = Path(__file__).resolve().parents[1] / "data" / "libraries" / "glue-dispensing"


@pytest.fixture()
def library(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # the cache folder of this test alone
    return Path(shutil.copytree(GLUE, tmp_path / "glue-dispensing"))


class Parses:
    """``load_task``, counting the times it really reads YAML."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.count = 0
        self._load = plugnproduce.description.taskfile.load_task
        monkeypatch.setattr(plugnproduce.description.taskfile, "load_task", self)

    def __call__(self, path: str | Path) -> Task:
        self.count += 1
        return self._load(path)


def test_an_unchanged_task_file_is_read_back_and_an_edited_one_read_anew(library: Path,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    parses, task_file = Parses(monkeypatch), library / "tasks" / "glue.yaml"
    first = service.task(task_file)
    again = service.task(task_file)
    assert parses.count == 1 and again == first and again.file == first.file == str(task_file)
    task_file.write_text(task_file.read_text(encoding="utf-8").replace("task: ", "task: edited-", 1),
                         encoding="utf-8")
    assert service.task(task_file).name == "edited-" + first.name and parses.count == 2


def test_a_bad_task_file_is_said_every_time_and_never_kept(library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    parses, task_file = Parses(monkeypatch), library / "tasks" / "glue.yaml"
    task_file.write_text("task: t\nsteps: 3\n", encoding="utf-8")
    for _ in range(2):
        with pytest.raises(DescriptionError) as said:
            service.task(task_file)
        assert said.value.file == str(task_file) and said.value.line == 2
    assert parses.count == 2 and not list((library.parent / "cache").rglob("task-*.pickle"))


def test_a_damaged_kept_task_is_read_again(library: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    parses, task_file = Parses(monkeypatch), library / "tasks" / "glue.yaml"
    first = service.task(task_file)
    (kept,) = (library.parent / "cache").rglob("task-*.pickle")
    kept.write_bytes(b"\x80\x05damaged")
    assert service.task(task_file) == first == service.task(task_file) and parses.count == 2


def test_a_moved_cell_file_lists_the_library_beside_it(library: Path) -> None:
    cell = library / "cells" / "glue-cell.yaml"
    assert cell_libraries(cell) == [library] == cell_libraries(cell)
    moved = library.parent / "moved"
    library.rename(moved)
    assert cell_libraries(moved / "cells" / "glue-cell.yaml") == [moved]  # the same content elsewhere


def test_a_kept_cell_whose_library_folder_went_away_says_so(library: Path, tmp_path: Path) -> None:
    cell = tmp_path / "cells" / "c.yaml"
    cell.parent.mkdir()
    cell.write_text(f"cell: c\nlibraries:\n  - {library}\ndevices:\n  - dispenser\n", encoding="utf-8")
    assert cell_libraries(cell) == [library]
    shutil.rmtree(library)
    with pytest.raises(DescriptionError, match="not found") as said:
        cell_libraries(cell)
    assert said.value.line == 3


def test_a_cell_file_named_relatively_is_read_as_the_file_in_each_working_folder(library: Path, tmp_path: Path,
                                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    text = "cell: same\ndevices:\n  - robot.ttl\n"
    for name in ("a", "b"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "cell.yaml").write_text(text, encoding="utf-8")
    for name in ("a", "b", "a"):
        monkeypatch.chdir(tmp_path / name)
        assert cell_device_files("cell.yaml") == ("same", [((tmp_path / name / "robot.ttl").resolve(), 3)])
