"""The long fuzz run's budgets and its printed counts (``scripts/fuzz.py``)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "fuzz.py"


@pytest.fixture(scope="module")
def fuzz() -> ModuleType:
    spec = importlib.util.spec_from_file_location("fuzz_script", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_a_case_slowed_by_a_busy_machine_is_no_overrun(fuzz: ModuleType) -> None:
    budget = fuzz.Budget(cpu=5.0, wall=60.0, mb=200.0)
    assert budget.overrun(cpu=2.0, wall=30.0, mb=10.0) is None  # waited for the cores, did little work


def test_each_budget_is_named_when_a_case_exceeds_it(fuzz: ModuleType) -> None:
    budget = fuzz.Budget(cpu=5.0, wall=60.0, mb=200.0)
    assert budget.overrun(cpu=6.0, wall=7.0, mb=0.0).startswith("overrun (6.0 s CPU;")
    assert budget.overrun(cpu=0.1, wall=61.0, mb=0.0).startswith("overrun (61.0 s wall-clock;")  # a sleep, a hang
    assert budget.overrun(cpu=0.1, wall=1.0, mb=300.0).startswith("overrun (+300 MB;")


def test_a_child_process_s_cpu_time_is_counted(fuzz: ModuleType) -> None:
    before = fuzz._cpu_seconds()
    subprocess.run([sys.executable, "-c", "sum(range(3 * 10**7))"], check=True, timeout=300)
    assert fuzz._cpu_seconds() - before > 0.1  # the child's work, not only this process's


def test_a_short_run_prints_its_table_and_exits_0(tmp_path: Path) -> None:
    proc = subprocess.run([sys.executable, str(SCRIPT), "--cases", "40", "--seed", "3", "--targets",
                           "xirp,reference,ssdp", "--save", str(tmp_path)], capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].split() == ["target", "cases", "accepted", "refused", "tracebacks", "overruns", "cases/CPU", "s"]
    assert [line.split()[0] for line in lines[1:4]] == ["xirp", "reference", "ssdp"]
    assert lines[4].startswith("total: 40 cases in ") and "0 tracebacks, 0 overruns" in lines[4]
