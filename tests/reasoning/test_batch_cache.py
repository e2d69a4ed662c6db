"""A batch over unchanged files reads what it reasoned before from the user's cache folder; a change is seen."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce.batch import enginecache
from plugnproduce.cli import app
from tests.reasoning.conftest import TASKS, write

runner = CliRunner()
CONFIGS = [("paper", ["binpicking-pc", "gripper", "robot", "sensor3d"]), ("no-gripper", ["robot"]),
           ("two-grippers", ["gripper", "magnetic-gripper", "robot"])]


@pytest.fixture
def home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    return tmp_path / "home" / ".cache" / "plugnproduce"


def batch(tmp_path: Path, task: Path) -> list[dict[str, object]]:
    configs = write(tmp_path, "c.jsonl", "".join(json.dumps({"config": n, "devices": d}) + "\n" for n, d in CONFIGS))
    result = runner.invoke(app, ["batch", str(configs), "--task", str(task), "--workers", "1"])
    assert result.exit_code == 0, result.output
    return [json.loads(line) for line in result.stdout.splitlines()]


def test_a_second_batch_reads_the_kept_engine_and_answers_alike(tmp_path: Path, home: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    task = write(tmp_path, "t.yaml", (TASKS / "pick-and-place.yaml").read_text())
    first = batch(tmp_path, task)
    (kept,) = home.glob("batch-*.pickle")

    def no_reasoning(*args: object) -> object:
        raise AssertionError("reasoned again over unchanged files")

    monkeypatch.setattr("plugnproduce.batch.engine", no_reasoning)
    assert batch(tmp_path, task) == first
    assert [r["plausible"] for r in first] == [["pick-and-place"], [], []]


def test_a_changed_task_is_reasoned_again(tmp_path: Path, home: Path) -> None:
    task = write(tmp_path, "t.yaml", (TASKS / "pick-and-place.yaml").read_text())
    assert batch(tmp_path, task)[0]["plausible"] == ["pick-and-place"]
    task.write_text(task.read_text().replace("grip_force: 30", "grip_force: 400"))
    assert batch(tmp_path, task)[0]["plausible"] == []
    assert len(list(home.glob("batch-*.pickle"))) == 2


def test_a_damaged_kept_engine_is_rebuilt(tmp_path: Path, home: Path) -> None:
    task = write(tmp_path, "t.yaml", (TASKS / "pick-and-place.yaml").read_text())
    first = batch(tmp_path, task)
    (kept,) = home.glob("batch-*.pickle")
    kept.write_bytes(b"not a pickle")
    assert batch(tmp_path, task) == first
    assert kept.read_bytes() != b"not a pickle"


def test_an_unreadable_file_gives_no_key(tmp_path: Path) -> None:
    assert enginecache.digest((), None, [tmp_path / "missing.yaml"], 1) is None
    assert enginecache.digest((), None, [], 1) == enginecache.digest((), None, [], 1) != enginecache.digest((), None, [], 2)
