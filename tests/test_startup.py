"""The command line starts without importing what only its commands need (how fast: bench/bench_startup.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import plugnproduce
from plugnproduce.lazy import lazy_module

SRC = str(Path(plugnproduce.__file__).resolve().parents[1])
HEAVY = ("rdflib", "pyshacl", "owlready2", "xmlschema", "networkx", "clingo", "lxml", "rich", "aiohttp", "fastapi",
         "uvicorn", "async_upnp_client", "graphviz", "yaml", "pint", "numpy", "pydantic", "distributed",
         "plugnproduce.service", "plugnproduce.reasoning")
NOT_FOR_VALIDATE = ("owlready2", "networkx", "clingo", "aiohttp", "fastapi", "uvicorn", "async_upnp_client", "graphviz",
                    "pint", "numpy", "distributed", "plugnproduce.reasoning", "plugnproduce.codegen",
                    "plugnproduce.hmi", "plugnproduce.verification")
"""What validating a device, a task and a cell has no use for (the SHACL shapes need rdflib and pySHACL; units
come from the cached table, not pint)."""
ROOT = Path(__file__).resolve().parents[1]


def _run(code: str, home: Path | None = None) -> str:
    """What ``code`` prints in a fresh interpreter running this checkout (with ``home`` as its user's home)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get("PYTHONPATH"))))}
    if home is not None:
        env["HOME"] = str(home)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300,
                          check=True, cwd=ROOT).stdout


def _loaded_after(code: str, home: Path | None = None) -> set[str]:
    """The modules whose code has run in a fresh interpreter after ``code`` (lazy ones not yet used excluded)."""
    report = ("\nimport json, sys\n"
              "print(json.dumps(sorted(n for n, m in sys.modules.items() if type(m).__name__ != '_LazyModule')))")
    return set(json.loads(_run(code + report, home).splitlines()[-1]))


def _command(*args: str) -> str:
    return (f"import sys\nfrom plugnproduce.cli import app\nsys.argv = ['pnp', *{list(args)!r}]\n"
            "try:\n    app()\nexcept SystemExit:\n    pass")


def test_importing_the_command_line_loads_nothing_heavy() -> None:
    loaded = _loaded_after("import plugnproduce.cli")
    assert sorted(h for h in HEAVY if h in loaded) == []


def test_help_loads_nothing_heavy() -> None:
    loaded = _loaded_after(_command("--help"))
    assert sorted(h for h in HEAVY if h in loaded) == []


def test_validate_loads_neither_the_reasoner_nor_pint_once_the_units_are_cached(tmp_path: Path) -> None:
    """The first process to read a unit asks pint and keeps the answer in the user's cache folder; the next
    validation of the same files reads units from there and loads nothing it has no use for."""
    files = ("descriptions/devices/gripper.ttl", "descriptions/devices/robot.ttl", "descriptions/tasks/bin-picking.yaml",
             "descriptions/cells/bin-picking.yaml")
    first = _loaded_after(_command("validate", *files), tmp_path)
    assert "pint" in first and list((tmp_path / ".cache" / "plugnproduce").glob("units-*.json"))
    again = _loaded_after(_command("validate", *files), tmp_path)
    assert "rdflib" in again and "pyshacl" in again  # it did validate
    assert sorted(h for h in NOT_FOR_VALIDATE if h in again) == []


def test_a_lazy_module_loads_on_first_use() -> None:
    code = ("import sys\nfrom plugnproduce.lazy import lazy_module\n"
            "m = lazy_module('plugnproduce.drawing')\n"
            "print('plugnproduce.drawing' in sys.modules, 'graphviz' in sys.modules, lazy_module('plugnproduce.drawing') is m)\n"
            "m.draw_chart\n"  # first use: the module's code runs now
            "print('graphviz' in sys.modules, m.draw_chart is sys.modules['plugnproduce.drawing'].draw_chart)")
    assert _run(code).split() == ["False", "False", "True", "True", "True"]


def test_a_name_the_module_binds_anew_after_first_use_is_seen_through_its_stand_in() -> None:
    code = ("from plugnproduce.lazy import lazy_module\n"
            "m = lazy_module('plugnproduce.drawing')\n"
            "m.draw_chart\n"  # first use
            "import plugnproduce.drawing as real\n"
            "real.draw_chart = 'patched'\n"  # as a test's monkeypatch or a module replacing a global does
            "print(m.draw_chart)")
    assert _run(code).split() == ["patched"]


def test_a_missing_module_is_an_error_at_once() -> None:
    with pytest.raises(ModuleNotFoundError, match="plugnproduce.nowhere"):
        lazy_module("plugnproduce.nowhere")


def test_a_submodule_imported_before_its_lazy_package_is_used_runs_once_after_its_package() -> None:
    # the import system reads the package's __path__; were that to run the package (which imports the same
    # submodule), the submodule would run twice and its registry of ASP predicates would exist twice
    code = ("import sys\nfrom plugnproduce.lazy import lazy_module\n"
            "lazy_module('plugnproduce.reasoning')\n"
            "from plugnproduce.reasoning.asp.terms import _REGISTRY\n"
            "from plugnproduce.reasoning.asp import solver\n"
            "import plugnproduce.reasoning.checks.linksafety\n"  # a package runs before its submodules: no partial import
            "print(solver.decode.__globals__['_REGISTRY'] is _REGISTRY)")
    assert _run(code).split() == ["True"]


def _help(home: Path, columns: str) -> tuple[str, set[str]]:
    code = ("import sys\nsys.argv = ['pnp', '--help']\nfrom plugnproduce.__main__ import run\n"
            "try:\n    run()\nexcept SystemExit:\n    pass\n"
            "import json\nprint(json.dumps(sorted(n for n, m in sys.modules.items() "
            "if type(m).__name__ != '_LazyModule')))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get("PYTHONPATH")))),
           "HOME": str(home), "COLUMNS": columns}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120,
                         check=True, cwd=ROOT).stdout
    text, _, modules = out.rpartition("\n[")
    return text, set(json.loads("[" + modules))


def test_help_is_printed_from_the_cache_folder_the_second_time(tmp_path: Path) -> None:
    """The first ``pnp --help`` runs the command line and keeps its text; the next prints that text without
    importing typer or click (a bare interpreter's start, about)."""
    first, loaded = _help(tmp_path, "100")
    assert "typer" in loaded and "Usage:" in first and "batch" in first
    again, loaded_again = _help(tmp_path, "100")
    assert again == first
    assert sorted(m for m in ("typer", "click", "plugnproduce.cli", "hashlib", *HEAVY) if m in loaded_again) == []
    narrow, loaded_narrow = _help(tmp_path, "60")  # another width: laid out again, by the command line
    assert "typer" in loaded_narrow and narrow != first
    assert max(map(len, narrow.splitlines())) <= 60 < max(map(len, first.splitlines()))


def test_plugging_a_simulated_device_loads_only_the_control_channel() -> None:
    """``pnp sim plug`` talks to a running simulated cell over its control channel: none of the network stack, the
    service or the executor (the controller's names are imported on first use)."""
    loaded = _loaded_after(_command("sim", "plug", "gripper", "--control", "127.0.0.1:1"))  # nothing listens there
    assert "plugnproduce.sim.control" in loaded
    unneeded = ("aiohttp", "async_upnp_client", "rdflib", "owlready2", "clingo", "plugnproduce.service",
                "plugnproduce.discovery", "plugnproduce.executor", "plugnproduce.protocols", "plugnproduce.sim.cell")
    assert sorted(h for h in unneeded if h in loaded) == []


@pytest.mark.parametrize("package", ["plugnproduce.reasoning", "plugnproduce.reasoning.asp", "plugnproduce.reasoning.checks",
                                     "plugnproduce.reasoning.repairs", "plugnproduce.reasoning.explanation",
                                     "plugnproduce.batch"])
def test_importing_the_reasoning_layer_loads_neither_a_reasoner_nor_its_other_parts(package: str) -> None:
    loaded = _loaded_after(f"import {package}")
    parts = ("plugnproduce.reasoning.", "plugnproduce.batch.")
    assert sorted(m for m in loaded if m in ("clingo", "owlready2", "rdflib", "pint", "distributed")
                  or (m.startswith(parts) and m != package)) == []


def test_the_reasoning_layer_loads_what_is_used_on_first_use() -> None:
    code = ("import sys\nimport plugnproduce.reasoning as r\nimport plugnproduce.reasoning.checks\n"
            "print('clingo' in sys.modules, r.check.__module__, r.repair.__module__, 'capabilities' in dir(r))\n"
            "from plugnproduce.reasoning import Repair, explain_offered\n"
            "print('clingo' in sys.modules, Repair.__name__, explain_offered.__module__)\n"
            "import plugnproduce.batch as b\n"
            "print([n for p in (r, b) for n in p.__all__ if getattr(p, n, None) is None] == [])")
    assert _run(code).split() == ["False", "plugnproduce.reasoning.checks.plausibility",
                                  "plugnproduce.reasoning.repairs.windows", "True",
                                  "True", "Repair", "plugnproduce.reasoning.explanation.why", "True"]


NOT_FOR_A_WARM_ANSWER = ("pydantic", "asyncio", "owlready2", "pyshacl", "xmlschema", "aiohttp", "fastapi", "uvicorn",
                         "async_upnp_client", "graphviz", "pint", "numpy", "distributed", "plugnproduce.codegen",
                         "plugnproduce.hmi", "plugnproduce.verification", "rdflib", "lxml", "networkx",
                         "plugnproduce.description.loader", "plugnproduce.batch", "plugnproduce.planning",
                         "plugnproduce.executor", "plugnproduce.service.batches", "plugnproduce.service.goals",
                         "plugnproduce.service.resumes", "yaml", "plugnproduce.safeio",
                         "plugnproduce.description.taskfile", "importlib.resources", "hashlib")
"""What answering ``pnp capabilities`` and ``pnp check`` from files seen before has no use for (typer turns the
file names into paths without pydantic; the event loop is started only by the commands that talk to devices;
the taxonomy, the processes, the cell's devices, the cell and task files and the cycle time come read and
reasoned from the cache folder, so neither RDF, XML nor YAML is parsed; the service loads only the use cases the
command calls; what is kept is named by CPython's own SHA-256, so OpenSSL is not loaded)."""

NOT_FOR_WARM_CAPABILITIES = ("decimal", "plugnproduce.description.paths", "plugnproduce.description.quantities.contracts",
                             "plugnproduce.description.quantities.units")
"""What a warm ``pnp capabilities`` has no use for besides: the ASP facts of the cell's devices and of the processes
come read back from the cache folder, so no chart's paths are searched and no number or unit is read."""


@pytest.mark.parametrize("args", [("capabilities", "--cell", "descriptions/cells/bin-picking.yaml"),
                                  ("check", "descriptions/tasks/bin-picking.yaml", "--cell",
                                   "descriptions/cells/bin-picking.yaml")])
def test_a_warm_capabilities_or_check_loads_nothing_it_has_no_use_for(tmp_path: Path, args: tuple[str, ...]) -> None:
    code = _command(*args).replace("pass", "print('exit', sys.exc_info()[1].code)")
    _run(code, tmp_path)  # the first answer keeps the units and the reasoned taxonomy in the cache folder
    out = _run(code + "\nprint('loaded: ' + ' '.join(sorted(sys.modules)))", tmp_path)
    answer = "9 of 12 process commands offered" if args[0] == "capabilities" else "bin-picking: plausible"
    assert answer in out and "exit 0" in out
    loaded = set(out.rsplit("loaded: ", 1)[1].split())
    unneeded = NOT_FOR_A_WARM_ANSWER + (NOT_FOR_WARM_CAPABILITIES if args[0] == "capabilities" else ())
    assert sorted(h for h in unneeded if h in loaded) == []  # a check's cycle time estimate (which
    # follows the specific process charts code generation builds) is read back too


NOT_FOR_THE_CONSOLE_SCRIPT = ("plugnproduce.cli.devices", "plugnproduce.cli.serve", "plugnproduce.cli.run",
                              "plugnproduce.cli.validate", "plugnproduce.cli.generate", "plugnproduce.cli.verify",
                              "plugnproduce.cli.knowledge", "plugnproduce.cli.plan", "plugnproduce.cli.teach",
                              "plugnproduce.cli.resume", "plugnproduce.cli.runs", "plugnproduce.cli.draw", "socket",
                              "csv", "tempfile", "platformdirs", *NOT_FOR_A_WARM_ANSWER)
"""What ``pnp capabilities`` and ``pnp check`` from files seen before have no use for, run as the console script: the
modules of the other commands (and what they import), the platform's folder names (the cache folder is named by
the rule platformdirs follows) and a temporary file's names (nothing is written)."""


@pytest.mark.parametrize("args", [("capabilities", "--cell", "descriptions/cells/bin-picking.yaml"),
                                  ("check", "descriptions/tasks/bin-picking.yaml", "--cell",
                                   "descriptions/cells/bin-picking.yaml")])
def test_the_console_script_imports_only_the_command_it_runs(tmp_path: Path, args: tuple[str, ...]) -> None:
    """``pnp`` imports the module of the command it runs, and makes the methods of only the dataclasses the answer
    uses: none of the SCXML model's, though the devices read back hold their charts."""
    code = (f"import sys\nsys.argv = ['pnp', *{list(args)!r}]\nfrom plugnproduce.__main__ import run\n"
            "try:\n    run()\n    code = 0\nexcept SystemExit as exc:\n    code = exc.code or 0\nprint('exit', code)\n"
            "from plugnproduce.statechart import model\n"
            "made = [n for n, c in vars(model).items() if isinstance(c, type) and '__dataclass_params__' in vars(c)]\n"
            "print('made: ' + ' '.join(made))\nprint('loaded: ' + ' '.join(sorted(sys.modules)))")
    _run(code, tmp_path)  # the first answer keeps what the next reads back
    out = _run(code, tmp_path)
    answer = "9 of 12 process commands offered" if args[0] == "capabilities" else "bin-picking: plausible"
    assert answer in out and "exit 0" in out
    loaded = set(out.rsplit("loaded: ", 1)[1].split())
    assert "plugnproduce.cli.reasoning" in loaded
    assert sorted(m for m in NOT_FOR_THE_CONSOLE_SCRIPT if m in loaded) == []
    assert out.split("made:", 1)[1].split("\n", 1)[0].split() == []


def test_the_console_script_keeps_what_its_start_made_out_of_the_collectors_walks_and_still_collects() -> None:
    """What importing the command line made (typer's classes, the commands) lives as long as the process: ``pnp``
    freezes it, so that the cyclic collector does not walk it again in every full collection while a command
    starts. The collector stays on: a cycle a command leaves behind is still collected."""
    code = ("import gc, sys, weakref\nsys.argv = ['pnp', '--version']\nfrom plugnproduce.__main__ import run\n"
            "try:\n    run()\nexcept SystemExit:\n    pass\n"
            "import typer\nwalked = gc.get_objects()\n"
            "print('walked', any(o is typer.Typer for o in walked), any(o is run for o in walked))\n"
            "class Cycle:\n    pass\n"
            "c = Cycle()\nc.me = c\ngone = weakref.ref(c)\ndel c, walked\ngc.collect()\n"
            "print('collected', gc.isenabled(), gone() is None)")
    out = _run(code)
    assert "pnp (plugnproduce)" in out
    assert "walked False False" in out and "collected True True" in out
