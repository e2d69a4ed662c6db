"""``pnp run bin-picking-until-empty.yaml --sim``: the robot picks each part where the bin-picking PC found it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import controller, service
from plugnproduce.sim.bin import SimulatedBin

TASKS = service.builtin("tasks")


def pnp(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "plugnproduce", *args], capture_output=True, text=True, timeout=600)


def journal_of(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]


SPEED = "20"
"""The simulated devices work 20 times faster than real time: what is asserted is where each part was picked,
never when (the bin's 12 parts take about 16 s of the devices' durations in real time)."""


@pytest.mark.parametrize(("parts", "seed"), [(None, 0), (12, 2)], ids=["default-bin", "12-parts-seed-2"])
def test_the_task_empties_a_simulated_bin_picking_each_part_where_it_was_found(tmp_path: Path, parts: int | None,
                                                                                  seed: int) -> None:
    """``None``: ``--sim`` alone. Without ``--bin-parts`` the simulated devices used to report their charts' fixed
    pose: the loop picked the same pose up to its maximum (300 steps) and said succeeded. A task that loops on a
    localized pose now gets a seeded bin of 5 parts, and the run says so."""
    journal = tmp_path / "run.jsonl"
    given = () if parts is None else ("--bin-parts", str(parts), "--bin-seed", str(seed))
    result = pnp("run", str(TASKS / "bin-picking-until-empty.yaml"), "--sim", *given, "--speed", SPEED,
                 "--journal", str(journal))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr
    if parts is None:
        assert result.stdout.splitlines()[0] == ("simulated bin: 5 parts at random poses (seed 0); "
                                                 "--bin-parts N for another")
        parts = 5
    records = journal_of(journal)
    found = [r for r in records if r["kind"] == "event" and r["event"] == "PartLocalized"]
    assert [r["params"]["outcome"] for r in found] == ["PartFound"] * parts + ["BinEmpty"]
    for reported in found[:-1]:  # the robot's next move goes where the bin-picking PC found the part
        after = records[records.index(reported) + 1:]
        move = next(r for r in after if r["kind"] == "command" and r["device"] == "robot")
        assert move["command"] == "MoveTo" and move["params"]["TargetPose"] == reported["params"]["part_pose"]
    flows = [r for r in records if r["kind"] == "value" and r["value"] == "localize.part_pose"]
    used = [r for r in flows if "used" in r]
    assert len(used) == parts and all(u["device"] == "robot" and u["parameter"] == "pick_pose" for u in used)
    for u in used:  # the journal says where each pose came from and where it went
        source = [r for r in flows[: flows.index(u)] if "produced" in r][-1]
        assert source["device"] == "binpicking-pc" and source["produced"] == u["used"]
    placed = sorted(p.pose for p in SimulatedBin(parts, seed).parts)
    assert sorted(r["params"]["part_pose"] for r in found[:-1]) == placed  # each part once: the bin is empty
    last = records.index(found[-1])
    assert not [r for r in records[last:] if r["kind"] == "command"]  # the loop ended on BinEmpty
    assert records[-1]["kind"] == "end" and records[-1]["outcome"] == "succeeded"


def test_picking_at_a_fixed_pose_where_no_part_lies_fails_with_a_clear_fault(tmp_path: Path) -> None:
    result = pnp("run", str(TASKS / "bin-picking.yaml"), "--sim", "--bin-parts", "3", "--json",
                 "--journal", str(tmp_path / "run.jsonl"))
    assert result.returncode == 1
    fault = json.loads(result.stdout)["fault"]
    assert fault["device"] == "robot" and "no part at pose 0.4 0.1 0.05 0 180 0 in the bin" in fault["message"]


def test_a_bin_needs_simulated_devices() -> None:
    result = pnp("run", str(TASKS / "bin-picking-until-empty.yaml"), "--cell",
                 str(service.builtin("cells", "bin-picking.yaml")), "--bin-parts", "3")
    assert result.returncode == 2 and "--bin-parts works on simulated devices" in result.stderr


def test_only_a_task_that_loops_on_an_outcome_and_takes_a_localized_pose_gets_a_default_bin() -> None:
    assert controller.default_bin_parts(TASKS / "bin-picking.yaml") is None  # its fixed pick pose: no bin
    assert controller.default_bin_parts(TASKS / "bin-picking-localized.yaml") is None  # three rounds: the charts' poses
    assert controller.default_bin_parts(TASKS / "bin-picking-until-empty.yaml") == 5
