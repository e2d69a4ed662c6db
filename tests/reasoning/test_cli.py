"""``pnp capabilities``, ``check``, ``repair``, ``explain`` and ``batch`` through the command line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import yaml
from typer.testing import CliRunner

from plugnproduce.cli import app
from tests.reasoning.conftest import BIN_PICKING, DESCRIPTIONS, TASKS, write

runner = CliRunner()
INVALID = str(TASKS / "bin-picking-invalid.yaml")
VALID = str(TASKS / "bin-picking.yaml")
CELL = str(BIN_PICKING)


def pnp(*args: str):
    return runner.invoke(app, list(args))


def cell_file(tmp_path: Path, *devices: str) -> str:
    lines = "".join(f"  - {DESCRIPTIONS / 'devices' / d}.ttl\n" for d in devices)
    return str(write(tmp_path, "cell.yaml", f"cell: test\ndevices:\n{lines}"))


def test_capabilities_lists_offered_commands_and_reasons() -> None:
    result = pnp("capabilities", "--cell", CELL)
    assert result.exit_code == 0, result.output
    assert "9 of 12 process commands offered" in result.stdout
    assert "pick-and-place   gripper=gripper robot=robot" in result.stdout
    assert "needs a device that can screw;" in result.stdout and "pnp:" not in result.stdout
    verbose = pnp("capabilities", "--cell", CELL, "--verbose").stdout
    assert "pnp:CanScrew" in verbose and "screw.ttl:" in verbose


def test_capabilities_json() -> None:
    doc = json.loads(pnp("capabilities", "--cell", CELL, "--json").stdout)
    assert {"pick", "place", "pick-and-place", "bin-pick"} <= {o["command"] for o in doc["offered"]}


def test_capabilities_shows_one_binding_and_their_number_unless_all_are_asked_for(tmp_path: Path) -> None:
    cell = cell_file(tmp_path, "robot", "scara", "gripper", "magnetic-gripper")
    few = pnp("capabilities", "--cell", cell)
    assert "pick             gripper=gripper robot=robot  (1 of 4 bindings)" in few.stdout
    every = pnp("capabilities", "--cell", cell, "--all-bindings")
    assert ("pick             gripper=gripper robot=robot | gripper=gripper robot=scara | "
            "gripper=magnetic-gripper robot=robot | gripper=magnetic-gripper robot=scara\n") in every.stdout
    doc = json.loads(pnp("capabilities", "--cell", cell, "--json").stdout)
    pick = next(o for o in doc["offered"] if o["command"] == "pick")
    assert pick["bindings"] == [{"gripper": "gripper", "robot": "robot"}]
    assert pick["binding_count"] == 4
    assert pick["role_devices"] == {"gripper": ["gripper", "magnetic-gripper"], "robot": ["robot", "scara"]}
    listed = json.loads(pnp("capabilities", "--cell", cell, "--json", "--all-bindings").stdout)
    assert len(next(o for o in listed["offered"] if o["command"] == "pick")["bindings"]) == 4


def test_explain_says_the_missing_skill_is_can_grip(tmp_path: Path) -> None:
    cell = cell_file(tmp_path, "robot", "sensor3d", "binpicking-pc")
    result = pnp("explain", "--cell", cell, "pick-and-place")
    assert result.exit_code == 1
    assert "pick and place is not offered" in result.stdout and "the skill 'can grip'" in result.stdout
    assert "pnp:" not in result.stdout and ".ttl" not in result.stdout
    assert "add device 'gripper' (Parallel gripper) to the cell" in result.stdout
    verbose = pnp("explain", "--cell", cell, "pick-and-place", "--verbose").stdout
    assert "pick-and-place.ttl:" in verbose and "requiresSkill CanGrip" in verbose and "explain.lp:" in verbose


def test_explain_an_offered_process() -> None:
    result = pnp("explain", "--cell", CELL, "pick")
    assert result.exit_code == 0
    assert result.stdout.splitlines()[0] == "pick is offered in cell 'bin-picking': every role can be filled"
    assert "  - role 'gripper' can be filled by device 'gripper'" in result.stdout
    assert "every 'parallel gripper' has the skill 'can grip'" in result.stdout
    assert "http" not in result.stdout and "pnp:" not in result.stdout


def test_explain_depth_keeps_the_first_levels() -> None:
    result = pnp("explain", "--cell", CELL, "pick", "--depth", "1")
    assert result.stdout.splitlines()[1:3] == ["  - role 'gripper' can be filled by device 'gripper'",
                                              "  - role 'robot' can be filled by device 'robot'"]
    assert "parallel gripper" not in result.stdout


def test_explain_json_gives_the_derivation_tree() -> None:
    doc = json.loads(pnp("explain", "--cell", CELL, "pick", "--json").stdout)
    assert doc["offered"] is True and doc["answer"] is True
    flat = json.dumps(doc["derivation"], ensure_ascii=False)
    assert "ParallelGripper \u2291 \u2203hasSkill.CanParallelGrip" in flat and "pnp.ttl:" in flat
    assert "roles.lp:" in flat and "offered.lp:" in flat and "gripper.scxml:" in flat


def test_check_exits_1_naming_step_gripper_state_and_need() -> None:
    result = pnp("check", INVALID, "--cell", CELL)
    assert result.exit_code == 1
    line = next(x for x in result.stdout.splitlines() if "step 2" in x)
    assert "bin-picking-invalid.yaml:8:" in line
    assert "'gripper'" in line and "'closed'" in line and line.endswith("the step needs it open")
    assert "pnp:" not in result.stdout and "rests on" not in result.stdout
    verbose = pnp("check", INVALID, "--cell", CELL, "--verbose").stdout
    assert "needs it open (pnp:Open)" in verbose and "rests on:" in verbose and "gripper.scxml:" in verbose


def test_check_of_the_bin_picking_task_exits_0() -> None:
    result = pnp("check", VALID, "--cell", CELL)
    assert result.exit_code == 0 and "plausible" in result.stdout


def test_check_json() -> None:
    doc = json.loads(pnp("check", INVALID, "--cell", CELL, "--json").stdout)
    assert doc["plausible"] is False
    p = doc["problems"][0]
    assert (p["step"], p["device"], p["state"], p["needed"]) == (2, "gripper", "closed",
                                                                 "http://plugnproduce.org/ontology#Open")


def test_repair_ranks_inserting_open_gripper_last_for_it_drops_the_part() -> None:
    result = pnp("repair", INVALID, "--cell", CELL, "--top", "3")
    assert result.exit_code == 0, result.output
    last = result.stdout.split("repair 3 (cost 2):")[1]
    assert "insert open-gripper before step 2 (bin-pick)" in last
    assert "side effect: step 2 (open-gripper) opens device 'gripper', which holds the part" in last
    body = "\n".join(line[4:] for line in last.split("resulting task:\n")[1].splitlines())
    assert [s["command"] for s in yaml.safe_load(body)["steps"]] == ["bin-pick", "open-gripper", "bin-pick", "place"]
    first = result.stdout.split("repair 1 (cost 3):")[1].split("repair 2")[0]
    assert "insert place before step 2 (bin-pick)" in first and "drops" not in first


def test_repair_json_with_a_catalogue(tmp_path: Path) -> None:
    cell = cell_file(tmp_path, "robot", "sensor3d", "binpicking-pc")
    doc = json.loads(pnp("repair", VALID, "--cell", cell, "--catalogue", str(DESCRIPTIONS / "devices"),
                         "--json").stdout)
    assert doc["repairs"][0]["added_devices"] == ["gripper"]


def test_explain_a_step() -> None:
    result = pnp("explain", INVALID, "--cell", CELL, "--step", "2")
    assert result.exit_code == 1
    assert "device 'gripper' is in state 'closed' ('closed'); role 'gripper' needs it 'open'" in result.stdout
    assert "if device 'gripper' were in state 'open' (open) when step 2 starts" in result.stdout


def test_bad_input_is_one_line_and_exit_2(tmp_path: Path) -> None:
    for args in (("check", str(tmp_path / "missing.yaml"), "--cell", CELL),
                 ("explain", "--cell", CELL, "teleport"),
                 ("explain", INVALID, "--cell", CELL, "--step", "9"),
                 ("batch",),
                 ("batch", "--generate", "3", "--sizes", "20-30")):
        result = pnp(*args)
        assert result.exit_code == 2, args
        assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.output


def test_batch_generates_and_writes_jsonl_and_csv(tmp_path: Path) -> None:
    out = tmp_path / "out.jsonl"
    result = pnp("batch", "--generate", "40", "--sizes", "2-6", "--seed", "1", "--catalogue",
                 str(DESCRIPTIONS / "devices"), "-o", str(out), "--task", VALID, "--workers", "1")
    assert result.exit_code == 0, result.output
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(rows) == 40 and set(rows[0]) == {"config", "devices", "offered", "plausible", "purchase"}
    configs = write(tmp_path, "c.jsonl", json.dumps({"config": "paper", "devices": ["robot", "gripper"]}) + "\n")
    table = tmp_path / "out.csv"
    assert pnp("batch", str(configs), "-o", str(table), "--workers", "1").exit_code == 0
    assert table.read_text().splitlines()[1].startswith("paper,robot gripper,close-gripper")


def test_batch_counts_ambiguous_apart_from_impossible(tmp_path: Path) -> None:
    configs = write(tmp_path, "c.jsonl", "".join(json.dumps({"config": n, "devices": d}) + "\n" for n, d in (
        ("paper", ["binpicking-pc", "gripper", "robot", "sensor3d"]), ("two-grippers", ["gripper", "magnetic-gripper",
         "robot"]), ("cobot", ["cobot", "gripper"]), ("no-robot", ["gripper"]))))
    out = tmp_path / "out.jsonl"
    result = pnp("batch", str(configs), "--task", str(TASKS / "pick-and-place.yaml"), "-o", str(out), "--workers", "1")
    assert result.exit_code == 0, result.output
    assert result.stderr == (f"wrote 4 configurations to {out}: 1 all tasks plausible, 1 with a purchase, "
                             "1 ambiguous (bind a role), 1 impossible\n")
    purchases = [json.loads(line)["purchase"] for line in out.read_text().splitlines()]
    assert purchases[0] is None and set(purchases[1]) == {"options", "ambiguous"}
    assert set(purchases[2]) == {"options", "impossible"} and purchases[3]["options"][0]["add"] == ["robot"]


def test_batch_reads_configurations_from_standard_input() -> None:
    lines = json.dumps({"config": "no-gripper", "devices": ["binpicking-pc", "robot", "sensor3d"]}) + "\n"
    result = runner.invoke(app, ["batch", "-", "--task", VALID, "--workers", "1", "--top", "2"], input=lines)
    assert result.exit_code == 0, result.output
    (row,) = map(json.loads, result.stdout.splitlines())
    assert row["config"] == "no-gripper" and row["plausible"] == []
    assert [o["add"] for o in row["purchase"]["options"]][0] == ["gripper"]


def test_batch_names_the_line_of_an_unknown_device(tmp_path: Path) -> None:
    configs = write(tmp_path, "c.jsonl", '{"config": "a", "devices": ["robot"]}\n{"devices": ["hoverboard"]}\n')
    result = pnp("batch", str(configs), "--workers", "1")
    assert result.exit_code == 2 and result.stderr.startswith(f"{configs}:2: device 'hoverboard'")


def test_the_real_command_line_exits_1_on_the_invalid_task() -> None:
    result = subprocess.run([sys.executable, "-m", "plugnproduce", "check", INVALID, "--cell", CELL],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 1 and "'closed'" in result.stdout
