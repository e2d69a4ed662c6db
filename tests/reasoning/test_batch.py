"""Batch feasibility of many configurations."""

from __future__ import annotations

from pathlib import Path

import pytest

from plugnproduce import service
from plugnproduce.errors import DescriptionError
from plugnproduce.reasoning import Configuration, generate, read_configurations
from tests.reasoning.conftest import task, write

PAPER = ("binpicking-pc", "gripper", "robot", "sensor3d")


def rows(configs: list[Configuration], workers: int = 1):
    tasks = [task("bin-picking"), task("pick-and-place")]
    return list(service.batch(configs, service.catalogue(), tasks, workers=workers))


def test_the_paper_cell_runs_both_tasks() -> None:
    (row,) = rows([Configuration("paper", PAPER)])
    assert {"pick", "place", "bin-pick"} <= set(row.offered)
    assert row.plausible == ("bin-picking", "pick-and-place") and row.cheapest == {}


def test_the_cheapest_device_to_add_is_named() -> None:
    (row,) = rows([Configuration("no-gripper", ("binpicking-pc", "robot", "sensor3d"))])
    assert row.plausible == ()
    assert row.cheapest == {"bin-picking": "gripper", "pick-and-place": "magnetic-gripper"}


def test_none_when_one_device_is_not_enough() -> None:
    (row,) = rows([Configuration("sensor-only", ("sensor3d",))])
    assert row.cheapest == {"bin-picking": None, "pick-and-place": None}


def test_two_workers_give_the_same_rows_as_one() -> None:
    configs = generate(service.catalogue(), 300, (2, 5), seed=3)
    assert rows(configs, workers=2) == rows(configs, workers=1)


def test_generation_is_deterministic_and_sized() -> None:
    a = generate(service.catalogue(), 50, (2, 6), seed=1)
    assert a == generate(service.catalogue(), 50, (2, 6), seed=1)
    assert all(2 <= len(c.devices) <= 6 and len(set(c.devices)) == len(c.devices) for c in a)


def test_configurations_from_jsonl_and_csv(tmp_path: Path) -> None:
    jsonl = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot", "gripper"]}\n\n')
    table = write(tmp_path, "c.csv", "config,devices\na,robot gripper\n")
    assert read_configurations(jsonl) == read_configurations(table) == [Configuration("a", ("robot", "gripper"))]


def test_a_bad_configuration_line_is_bad_input(tmp_path: Path) -> None:
    bad = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot"]}\n{"config": "b"}\n')
    with pytest.raises(DescriptionError) as err:
        read_configurations(bad)
    assert err.value.line == 2


def test_an_unknown_device_is_bad_input() -> None:
    with pytest.raises(KeyError, match="hoverboard"):
        rows([Configuration("x", ("hoverboard",))])
