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
         "uvicorn", "async_upnp_client", "graphviz", "yaml", "plugnproduce.service", "plugnproduce.reasoning")


def _run(code: str) -> str:
    """What ``code`` prints in a fresh interpreter running this checkout."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (SRC, os.environ.get("PYTHONPATH"))))}
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120,
                          check=True).stdout


def _loaded_after(code: str) -> set[str]:
    """The modules whose code has run in a fresh interpreter after ``code`` (lazy ones not yet used excluded)."""
    report = ("\nimport json, sys\n"
              "print(json.dumps(sorted(n for n, m in sys.modules.items() if type(m).__name__ != '_LazyModule')))")
    return set(json.loads(_run(code + report).splitlines()[-1]))


def test_importing_the_command_line_loads_nothing_heavy() -> None:
    loaded = _loaded_after("import plugnproduce.cli")
    assert sorted(h for h in HEAVY if h in loaded) == []


def test_help_loads_nothing_heavy() -> None:
    code = ("import sys\nfrom plugnproduce.cli import app\nsys.argv = ['pnp', '--help']\n"
            "try:\n    app()\nexcept SystemExit:\n    pass")
    loaded = _loaded_after(code)
    assert sorted(h for h in HEAVY if h in loaded) == []


def test_a_lazy_module_loads_on_first_use() -> None:
    code = ("import sys\nfrom plugnproduce.lazy import lazy_module\n"
            "m = lazy_module('plugnproduce.drawing')\n"
            "print('plugnproduce.drawing' in sys.modules, 'graphviz' in sys.modules, lazy_module('plugnproduce.drawing') is m)\n"
            "m.draw_chart\n"  # first use: the module's code runs now
            "print('graphviz' in sys.modules, m.draw_chart is sys.modules['plugnproduce.drawing'].draw_chart)")
    assert _run(code).split() == ["False", "False", "True", "True", "True"]


def test_a_missing_module_is_an_error_at_once() -> None:
    with pytest.raises(ModuleNotFoundError, match="plugnproduce.nowhere"):
        lazy_module("plugnproduce.nowhere")


def test_a_submodule_imported_before_its_lazy_package_is_used_runs_once_after_its_package() -> None:
    # the import system reads the package's __path__; were that to run the package (which imports the same
    # submodule), the submodule would run twice and its registry of ASP predicates would exist twice
    code = ("import sys\nfrom plugnproduce.lazy import lazy_module\n"
            "lazy_module('plugnproduce.reasoning')\n"
            "from plugnproduce.reasoning.terms import _REGISTRY\n"
            "from plugnproduce.reasoning import solver\n"
            "import plugnproduce.reasoning.linksafety\n"  # a package runs before its submodules: no partial import
            "print(solver.decode.__globals__['_REGISTRY'] is _REGISTRY)")
    assert _run(code).split() == ["True"]
