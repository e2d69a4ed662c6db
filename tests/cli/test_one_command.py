"""The console script builds only the command it runs (typer builds every command's parameters otherwise), and
answers exactly as the whole command line does; its help and a misspelt command still see every command."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

import plugnproduce
from plugnproduce.cli import app
from plugnproduce.cli.application import _app_for

ROOT = Path(__file__).resolve().parents[2]
CELL = ROOT / "descriptions" / "cells" / "bin-picking.yaml"
TASK = ROOT / "descriptions" / "tasks" / "bin-picking.yaml"
SRC = str(Path(plugnproduce.__file__).resolve().parents[1])


def _built(args: list[str]) -> list[str]:
    return sorted(typer.main.get_command(_app_for(args)).commands)  # type: ignore[attr-defined]


@pytest.mark.parametrize("args, built", [
    (["capabilities", "--cell", "c.yaml"], ["capabilities"]),
    (["--library", "lib", "--no-builtin", "check", "t.yaml"], ["check"]),
    (["--library=lib", "repair", "t.yaml"], ["repair"]),
    (["sim", "plug", "gripper"], ["sim"]),
])
def test_the_command_run_is_the_only_one_built(args: list[str], built: list[str]) -> None:
    assert _built(args) == built


@pytest.mark.parametrize("args", [["--help"], ["--help", "check"], ["--version"], ["capabilitiez"], []])
def test_help_version_and_a_misspelt_command_see_every_command(args: list[str]) -> None:
    every = sorted(typer.main.get_command(app).commands)  # type: ignore[attr-defined]
    assert len(every) > 10 and _built(args) == every


@pytest.mark.parametrize("args", [["capabilities", "--cell", str(CELL)], ["check", str(TASK), "--cell", str(CELL)],
                                  ["check", str(TASK), "--cell", str(CELL), "--json"]])
def test_the_console_script_answers_as_the_whole_command_line(args: list[str]) -> None:
    whole = CliRunner().invoke(app, args)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get("PYTHONPATH"))))}
    alone = subprocess.run([sys.executable, "-m", "plugnproduce", *args], env=env, capture_output=True, text=True,
                           timeout=300, check=False)
    assert (alone.returncode, alone.stdout) == (whole.exit_code, whole.stdout)


def test_the_console_script_imports_the_module_that_registers_the_command_it_runs() -> None:
    """``pnp`` imports only the module :data:`~plugnproduce.cli.application.COMMANDS` names for the command: each
    command and group is registered by that module, and every module of the command line is in the list the help
    imports."""
    from typer.main import get_command_name

    from plugnproduce.cli import application

    registered = {c.name or get_command_name(c.callback.__name__): c.callback.__module__
                  for c in app.registered_commands if c.callback is not None}
    registered |= {g.name: g.typer_instance.registered_commands[0].callback.__module__
                   for g in app.registered_groups if g.name and g.typer_instance}
    assert registered == {name: f"plugnproduce.cli.{m}" for name, m in application.COMMANDS.items()}
    modules = {p.stem for p in Path(application.__file__).parent.glob("*.py")} - {"__init__", "application"}
    assert sorted(application.COMMAND_MODULES) == sorted(modules)
