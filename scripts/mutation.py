"""Mutation testing of the guard and core modules: does a test fail when the code is changed?

    python scripts/mutation.py                    # every module and encoding
    python scripts/mutation.py evaluator tokens   # some of them (names below, or --list)
    python scripts/mutation.py rules-chain        # one ASP encoding (rules/chain.lp; see mutation_asp.py)
    python scripts/mutation.py --jobs 2 --work build/mutation
    python scripts/mutation.py --again evaluator  # only the last run's survivors, with the tests as they are now
                                                  # (a whole run again if the module's list of tests changed)
    python scripts/mutation.py --only 'xǁFeasibilityǁ__init__' --only x__key_masks reasoning-feasibility
                                                  # only the mutants of some functions (mutmut's keys, * allowed)

For each guard module, mutmut (3.x, the ``test`` extra) makes small changes to its guard
functions, one at a time (``<`` for ``<=``, ``and`` for ``or``, a string or number changed,
an argument dropped, a ``return`` emptied, ...) and runs only the tests named for that module
below; of those, only the tests that reach the changed function. A mutant is *killed* when
a test fails, *survived* when every test passes. Printed per module: mutants, killed,
survived, timeouts, equivalent, and each survivor at its ``file:line`` with the change.

Each survivor is then run again against all of the module's tests by pytest (mutmut
runs a mutant only against the tests it saw reach the function); ``--again`` does only this,
for the last run's survivors, with the checkout's tests, and keeps every other result.
A survivor that cannot change any behaviour (an equivalent mutant) is listed with the
reason in ``scripts/mutation_equivalent.txt``; it is printed as such, does not count as
a survivor, and is not run again. Exit 0 when no mutant survives, 1 otherwise, 2 when the run itself fails.

The ASP encodings (``rules-NAME`` for ``rules/NAME.lp``) are changed by scripts/mutation_asp.py
instead (delete a rule, drop a body literal, flip a comparison), and reported the same way, with
the mutants clingo refuses counted apart. Their equivalents are listed under the encoding's file
(and not run).

Each module runs in its own work folder (``--work``, default ``build/mutation/NAME``) that
holds a copy of the checkout, so the checkout is never changed. Every pytest session there (the clean run,
mutmut's stats run, each mutant's run) keeps its results in an empty cache folder of its own (``caches/`` of the
work folder, removed when the session ends), its child processes too: all mutants share one mutated source, so
one digest, and the user's cache folder would give each the knowledge, devices, task files and cycle time
estimates the unmutated code kept there, without running the mutated function. mutmut only changes code
inside functions: a guard must live in a function to be tested here (module-level tables
such as allow-lists are exercised by the tests of the functions that read them).
"""

from __future__ import annotations

import argparse
import ast
import difflib
import json
import os
import re
import shutil
import subprocess
import sys
import time
import tomllib
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import mutation_asp
from mutation_asp import Target

ROOT = Path(__file__).resolve().parents[1]
EQUIVALENT_FILE = ROOT / "scripts" / "mutation_equivalent.txt"


@dataclass(frozen=True)
class Guard:
    """One guard module: the files mutated, which of their functions, and the tests that cover them."""

    name: str
    files: tuple[str, ...]
    tests: tuple[str, ...]
    functions: tuple[str, ...] = ("*",)
    """Patterns of mutmut's function keys (``x_name`` for a function, ``xǁClassǁmethod`` for a method)."""
    deselect: tuple[str, ...] = ()
    """Tests of those files left out (pytest node ids): slow ones that check something else than the module's
    behaviour, such as the W3C schema validation of a generated chart."""

    @property
    def selection(self) -> list[str]:
        """The pytest arguments that select the module's tests."""
        return [*self.tests, *(a for t in self.deselect for a in ("--deselect", t))]


GUARDS = (
    Guard("evaluator", ("src/plugnproduce/statechart/runtime/evaluator.py",
                     "src/plugnproduce/statechart/runtime/budgets.py"),
          ("tests/statechart/test_evaluator_guards.py", "tests/statechart/test_evaluator_budgets.py",
           "tests/statechart/test_interpreter.py")),
    Guard("safeio", ("src/plugnproduce/safeio.py",),
          ("tests/test_safeio_guards.py", "tests/test_safeio.py", "tests/test_safeio_yaml.py")),
    Guard("upnp-trust", ("src/plugnproduce/protocols/upnp/boundary.py", "src/plugnproduce/protocols/upnp/client.py",
                         "src/plugnproduce/protocols/upnp/discovery.py"),
          ("tests/protocols/test_upnp_trust.py", "tests/protocols/test_upnp_http_reading.py",
           "tests/protocols/test_upnp_loopback.py"),
          ("x__host_key", "x_check_trusted", "x_resolve_trusted", "xǁTrustedRequesterǁ*", "xǁNoRedirectRequesterǁ*",
           "x_load_device", "xǁUpnpDeviceClientǁfetch_files", "xǁUpnpDeviceClientǁfrom_found", "x_describe")),
    Guard("discovery-trust", ("src/plugnproduce/discovery/served.py",),
          ("tests/discovery/test_served.py",),
          ("x_read_served", "x__is_served_chart", "x__safe_name")),
    Guard("tokens", ("src/plugnproduce/hmi/security.py",),
          ("tests/hmi/test_security.py", "tests/hmi/test_route_tokens.py")),
    Guard("xirp-codec", ("src/plugnproduce/protocols/xirp/codec.py", "src/plugnproduce/protocols/xirp/decoding.py"),
          ("tests/protocols/test_xirp_guards.py", "tests/protocols/test_xirp_messages.py",
           "tests/protocols/test_xirp_robustness.py"),
          ("x__escaped", "x__attr", "x__checked", "x__name", "x__decimal", "x__write_pose", "x__value", "x__positive",
           "x_encode", "x_decode", "x__decode_document", "x__number", "x__integer", "x__pose", "x__decode_event")),
    Guard("executor-faults", ("src/plugnproduce/executor/run.py", "src/plugnproduce/executor/safestop.py"),
          ("tests/executor/test_faults.py", "tests/executor/test_run.py", "tests/executor/test_unanswered.py",
           "tests/executor/test_spinning_chart.py"),
          ("xǁTaskRunǁstop", "xǁTaskRunǁdevice_lost", "xǁTaskRunǁsend", "xǁTaskRunǁ_request",
           "x_stop_safely", "x__stop_device", "xǁTaskRunǁ_on_event", "xǁTaskRunǁ_on_lost",
           "xǁTaskRunǁ_on_anomaly", "xǁTaskRunǁ_on_step", "xǁTaskRunǁ_fault", "xǁTaskRunǁ_fail",
           "xǁTaskRunǁ_outcome", "xǁTaskRunǁ_send_one", "xǁTaskRunǁ_release", "xǁTaskRunǁ_deliver",
           "xǁTaskRunǁ_with_outcome")),
    Guard("executor-monitor", ("src/plugnproduce/executor/monitor.py",
                               "src/plugnproduce/description/quantities/contracts.py",
                               "src/plugnproduce/executor/outcomes.py"),
          ("tests/executor/test_monitor.py", "tests/executor/test_outcome_names.py",
           "tests/executor/test_unanswered.py")),
)

_S = "src/plugnproduce/"
_DEAD_END_BATCH = tuple(f"tests/reasoning/test_dead_end.py::{t}" for t in (
    "test_the_batch_says_what_check_says_for_every_configuration_with_or_without_the_dead_end",
    "test_the_batch_names_the_dead_end_as_the_reason_and_buys_a_gripper_that_can_close"))
# a loop whose steps are plausible but whose iteration moves its device on (loop_fixpoint), in check and batch
_LOOP_FIXPOINT = "tests/reasoning/test_loop_fixpoint.py"
_BATCH_WORKERS = tuple(f"tests/reasoning/test_batch.py::{t}" for t in (  # how the work is shared, not the answers
    "test_two_workers_give_the_same_rows_as_one", "test_workers_start_only_for_work_large_enough_to_repay_them"))
CORE = (
    Guard("codegen-flow", (_S + "codegen/flow.py",),
          ("tests/codegen/test_loops_and_links.py", "tests/codegen/test_branch_charts.py",
           "tests/codegen/test_nested_loop_charts.py"),
          deselect=("tests/codegen/test_loops_and_links.py::test_the_until_empty_chart_is_w3c_valid",
                    "tests/codegen/test_branch_charts.py::test_every_chart_of_the_branching_task_is_w3c_valid",
                    "tests/codegen/test_nested_loop_charts.py::test_the_nested_chart_is_w3c_valid")),
    Guard("description-outcomes", (_S + "description/outcomes.py",),
          ("tests/description/test_task_branches.py", "tests/validation/test_branch_findings.py",
           "tests/codegen/test_branch_charts.py", "tests/codegen/test_loops_and_links.py"),
          ("x_branch_of", "x_falling_under", "x_taken_by", "x__written", "x_flow_findings", "x_loop_ending",
           "x_ending_loop", "x_body_outcomes", "x__ends_on")),
    Guard("reasoning-plausibility", (_S + "reasoning/checks/plausibility.py",),
          ("tests/reasoning/test_plausibility.py", "tests/reasoning/test_branch_paths.py",
           "tests/reasoning/test_branch_check.py", "tests/reasoning/test_flow_check.py",
           "tests/reasoning/test_why.py", "tests/reasoning/test_link_findings.py",
           # a device that cannot leave its start state (stuck), in a library written outside the package
           "tests/reasoning/test_dead_end.py::test_check_says_a_device_that_cannot_leave_its_start_state_is_stuck_at_the_steps_line",
           "tests/reasoning/test_dead_end.py::test_the_problem_names_the_device_its_state_and_the_role",
           _LOOP_FIXPOINT)),
    Guard("codegen-specific", (_S + "codegen/specific.py",),
          ("tests/codegen/test_specific_values.py", "tests/codegen/test_task_chart.py",
           "tests/codegen/test_closed_world.py"),
          deselect=("tests/codegen/test_task_chart.py::test_every_chart_is_valid_w3c_scxml",
                    # the slowest runs of a closed world, and the one of a broken device model (the closed world's
                    # own test); three shipped tasks, another cell's and a hierarchical device's still run to done
                    "tests/codegen/test_closed_world.py::test_closed_world_chart_reaches_done[bin-picking-then-home]",
                    "tests/codegen/test_closed_world.py::test_closed_world_chart_reaches_done[bin-picking-until-empty]",
                    "tests/codegen/test_closed_world.py::test_closed_world_chart_reaches_done[bin-picking-in-rounds]",
                    "tests/codegen/test_closed_world.py::test_broken_device_model_does_not_reach_done")),
    Guard("description-flow", (_S + "description/flow.py",),
          ("tests/description/test_nested_loops.py", "tests/description/test_task_branches.py")),
    Guard("reasoning-branches", (_S + "reasoning/checks/branches.py",),
          ("tests/reasoning/test_branch_paths.py", "tests/reasoning/test_branch_check.py",
           "tests/reasoning/test_nested_loop_check.py")),
    Guard("reasoning-dataflow", (_S + "reasoning/checks/dataflow.py",),
          ("tests/reasoning/test_link_findings.py", "tests/reasoning/test_flow_check.py",
           "tests/reasoning/test_plausibility.py", "tests/reasoning/test_branch_check.py")),
    Guard("reasoning-feasibility", (_S + "batch/feasibility.py",),
          ("tests/reasoning/test_batch.py", *_DEAD_END_BATCH, _LOOP_FIXPOINT),
          deselect=(*_BATCH_WORKERS,  # they reach no line or branch of the module the other tests do not reach
                    "tests/reasoning/test_batch.py::test_answers_agree_with_the_full_reasoner_on_random_configurations")),
    Guard("reasoning-purchases", (_S + "batch/purchases.py",),
          ("tests/reasoning/test_batch.py", "tests/reasoning/test_batch_purchase_order.py", *_DEAD_END_BATCH,
           _LOOP_FIXPOINT),
          deselect=(*_BATCH_WORKERS,  # they compare offered and plausible only, never a purchase
                    "tests/reasoning/test_batch.py::test_answers_agree_with_the_full_reasoner_on_random_configurations")),
    Guard("reasoning-windows", (_S + "reasoning/repairs/windows.py",), ("tests/reasoning/test_windows.py",)),
    Guard("reasoning-lifting", (_S + "reasoning/repairs/lifting.py",),
          ("tests/reasoning/test_repair_lifting_placements.py", "tests/reasoning/test_repair_lifting.py")),
    Guard("executor-links", (_S + "executor/links.py",), ("tests/executor/test_links.py",)),
    Guard("executor-values", (_S + "executor/values.py",), ("tests/executor/test_values.py",)),
    *(Guard(f"verification-{name}", (_S + f"verification/{name}.py",),
            ("tests/verification/test_answers.py", "tests/verification/test_device_ends.py",  # the fast ones first
             "tests/verification/test_verify.py", "tests/verification/test_branch_verify.py",
             "tests/verification/test_nested_verify.py", "tests/verification/test_hierarchical_verify.py"),
            deselect=(  # a run on the simulated cell (the executor's work) and pnp verify in a child process
                "tests/verification/test_verify.py::test_the_seeded_deadlock_is_not_hit_by_a_simulated_run",
                "tests/verification/test_nested_verify.py::"
                "test_pnp_verify_proves_the_nested_task_on_the_bin_picking_cell"))
      for name in ("arguments", "results", "search", "trace", "world")),
)
"""The core modules (the answers users rely on), each with the smallest set of test files that covers it."""

_ENC, _CAP, _PLA, _WHY = ("tests/reasoning/test_encodings.py", "tests/reasoning/test_capabilities.py",
                          "tests/reasoning/test_plausibility.py", "tests/reasoning/test_why.py")
_REP, _WIN = "tests/reasoning/test_repair.py", "tests/reasoning/test_windows.py"
_STUCK = ("tests/reasoning/test_dead_end.py::"  # a device that cannot leave its start state: stuck/6 and its problem
          "test_check_says_a_device_that_cannot_leave_its_start_state_is_stuck_at_the_steps_line",
          "tests/reasoning/test_dead_end.py::test_the_problem_names_the_device_its_state_and_the_role")
_STUCK_WINDOWS = (_WIN + "::"  # plausible/2 without the stuck device's bad/3: the long task is repaired whole
                  "test_a_long_task_whose_only_problem_is_a_stuck_device_is_repaired_window_by_window")
ENCODINGS = tuple(Target(f"rules-{name}", f"rules/{name}.lp", tests) for name, tests in (
    ("roles", (_ENC, _CAP, _PLA)),
    ("offered", (_ENC, _CAP)),
    ("bindings", (_ENC, _CAP)),
    ("explain", (_ENC, _CAP, _WHY)),
    ("resolve", (_ENC, _PLA, _WHY, *_STUCK, _STUCK_WINDOWS)),
    ("chain", (_ENC, _PLA, _REP, _WHY, *_STUCK)),
    ("params", (_ENC, _PLA, _REP, "tests/reasoning/test_bounds.py")),
    ("provenance", (_ENC, _WHY)),
    ("repair", (_ENC, _REP, "tests/reasoning/test_repair_edits.py", "tests/reasoning/test_repair_lifting.py",
                # a reset names the limit of the device the step runs with, bound by the task or not
                "tests/reasoning/test_repair_device_terms.py::"
                "test_the_vacuum_gripper_is_bought_with_the_vacuum_its_limit_takes_and_says_why")),
    ("window", (_ENC, _WIN)),
    ("show_abilities", (_ENC, "tests/reasoning/test_batch.py")),
    ("show_capabilities", (_CAP, _WHY)),
    ("show_check", (_PLA, _WHY, *_STUCK)),
    ("show_derivation", (_WHY,)),
    ("show_repair", (_REP,)),
    ("show_window", (_WIN,)),
))
"""Each encoding with the reasoning tests that cover it, the fast table-driven ones first (``-x`` stops at the
first failure)."""

PLUGIN = "mutation_fresh_caches"
PLUGIN_TEXT = '''"""Mutation runs only: each pytest session gets a cache folder of its own, and the guard modules'
caches are emptied before each test."""

import os
import shutil
import tempfile

import pytest

_FOLDERS = []


def pytest_configure(config):
    """The session (the clean run, the stats run, one mutant's run) keeps its results in an empty cache folder of its
    own, which its child processes inherit: all mutants share one mutated source, so one digest, and a result kept
    by another session (made by the unmutated code or another mutant) would answer for this one's code."""
    folder = tempfile.mkdtemp(prefix="cache-", dir=os.environ.get("PNP_MUTATION_CACHES") or None)
    seed = os.environ.get("PNP_MUTATION_SEED")
    if seed and os.path.isdir(seed):  # what no mutated function makes (the taxonomy closures, the unit table)
        shutil.copytree(seed, folder, dirs_exist_ok=True)
    _FOLDERS.append((folder, os.environ.get("XDG_CACHE_HOME")))
    os.environ["XDG_CACHE_HOME"] = folder
    from plugnproduce.knowledge import cache, devicecache
    from plugnproduce.service import descriptions

    cache._FOLDERS.clear()  # what the process read while the tests were collected names another folder
    devicecache._SERVED.clear()
    descriptions._loaded.cache_clear()


def pytest_unconfigure(config):
    folder, before = _FOLDERS.pop()
    if before is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = before
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(autouse=True)
def _fresh_caches():
    from plugnproduce.protocols.xirp import codec
    from plugnproduce.statechart.runtime import evaluator

    evaluator._compile_expression.cache_clear()
    codec._NAMES.clear()
    yield
'''
"""A pytest plugin of the work folder: a cache filled by the unmutated code (in memory while the tests were
collected, or in the user's cache folder: the kept knowledge, devices, task files, cycle time estimates, taxonomy
closures) would otherwise answer for the mutated function."""

SEEDS = {"taxonomy": ("src/plugnproduce/ontology/taxonomy.py", "src/plugnproduce/ontology/sources.py",
                      "src/plugnproduce/safeio.py"),
         "units": ("src/plugnproduce/description/quantities/unitcache.py",
                   "src/plugnproduce/description/quantities/units.py")}
"""What each session's cache folder starts with, copied from the user's cache folder when the work folder is
prepared (``KIND-*.json``): HermiT's taxonomy closures (about 1.5 s of CPU each, most of what an empty cache folder
costs a session) and pint's unit table, with the files whose functions run while they are made: a module among
those starts without them."""

COPIED = ("src", "tests", "ontology", "rules", "descriptions", "pyproject.toml")
_KILLED = {1: "killed", 3: "killed"}
_TIMEOUT = {36, -24, 24, 152, 255, -9, -11}
_SURVIVED = {0: "survived", 33: "no tests", 5: "no tests"}


@dataclass(frozen=True)
class Survivor:
    """A mutant no test killed: where, and what was changed."""

    key: str
    where: str
    before: str
    after: str

    @property
    def function(self) -> str:
        """The mutated function's key (``x_name`` or ``xǁClassǁmethod``)."""
        return self.key.rsplit(".", 1)[-1].split("__mutmut_")[0]


def equivalents(path: Path = EQUIVALENT_FILE) -> dict[tuple[str, str, str], str]:
    """The listed equivalent mutants: (function, line before, line after) → why no behaviour can differ."""
    found: dict[tuple[str, str, str], str] = {}
    if not path.exists():
        return found
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip() or line.startswith("#"):
            continue
        parts = [p.strip() for p in line.split(" || ")]
        if len(parts) != 4:
            raise SystemExit(f"{path.relative_to(ROOT)}:{number}: expected 'function || before || after || why'")
        found[(parts[0], parts[1], parts[2])] = parts[3]
    return found


def _prepare(guard: Guard, work: Path) -> None:
    """A fresh copy of the checkout in ``work``, with the mutmut settings of ``guard``."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    for name in COPIED[:-1]:
        shutil.copytree(ROOT / name, work / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    settings = {
        "source_paths": ["src"],
        "only_mutate": list(guard.files),
        "also_copy": ["ontology", "rules", "descriptions"],
        "pytest_add_cli_args_test_selection": guard.selection,
        "pytest_add_cli_args": ["-p", "no:cacheprovider", "-p", PLUGIN, "-n", "0"],  # in mutmut's process
        # Each mutant runs in a process forked from a server that collected the tests but ran none, and
        # the plugin below empties the package's caches before each test, so that no value computed by
        # the unmutated code (a compiled expression, a checked name) hides the mutant.
        "process_isolation": "forkserver",
        # generous: on a busy machine a mutant's tests take several times the clean run's estimate, and a
        # survivor must not pass for a timeout
        "timeout_multiplier": 8.0,
        "timeout_constant": 5.0,
        # the wording of an error is not a guard (the condition that raises it is): raise lines are not mutated
        "do_not_mutate_patterns": [r"^\s*raise\s"],
        "use_git_change_detection": False,
        "track_dependencies": False,
    }
    lines = [f"{key} = {json.dumps(value)}" for key, value in settings.items()]
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    (work / "pyproject.toml").write_text(text + "\n[tool.mutmut]\n" + "\n".join(lines) + "\n", encoding="utf-8")
    (work / "mutants" / "src").mkdir(parents=True)  # on sys.path of the tests' child processes from the start
    (work / "src" / f"{PLUGIN}.py").write_text(PLUGIN_TEXT, encoding="utf-8")
    _seed(guard, work)


def _user_cache() -> Path:
    """The user's cache folder, as plugnproduce names it on Linux (``$XDG_CACHE_HOME`` when absolute)."""
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    return Path(xdg if os.path.isabs(xdg) else os.path.expanduser("~/.cache")) / "plugnproduce"


def _seed(guard: Guard, work: Path) -> None:
    """The kept results of :data:`SEEDS` no function of ``guard`` makes, from the user's cache folder, into the
    work folder's ``seed/`` (where each session's cache folder starts from)."""
    seed = work / "seed" / "plugnproduce"
    seed.mkdir(parents=True)
    for kind, makers in SEEDS.items():
        if not set(guard.files) & set(makers):
            for kept in sorted(_user_cache().glob(f"{kind}-*.json")):
                shutil.copy2(kept, seed)


def _selected_tests(work: Path) -> list[str]:
    """The test files a prepared work folder runs (mutmut starts afresh when they change)."""
    settings = tomllib.loads((work / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mutmut"]
    return list(settings["pytest_add_cli_args_test_selection"])


def _refresh_tests(work: Path) -> None:
    """The checkout's tests, copied again into a prepared work folder (to test the survivors again)."""
    for where in (work / "tests", work / "mutants" / "tests"):
        shutil.copytree(ROOT / "tests", where, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__"))


def _caches(work: Path) -> Path:
    """Where each pytest session of a work folder makes its own cache folder (removed when it ends)."""
    folder = work / "caches"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _run_mutmut(guard: Guard, work: Path, jobs: int, names: list[str] | None = None) -> None:
    env = {**os.environ, "PYTHONPATH": str(work / "mutants" / "src"), "PYTHONDONTWRITEBYTECODE": "1",
           "PNP_MUTATION_CACHES": str(_caches(work)), "PNP_MUTATION_SEED": str(work / "seed")}
    patterns = names or [f"*.{f}__mutmut_*" for f in guard.functions]
    command = [sys.executable, "-m", "mutmut", "run", "--max-children", str(jobs), *patterns]
    done = subprocess.run(command, cwd=work, env=env, capture_output=True, text=True)
    log = work / "mutmut.log"
    log.write_text(done.stdout + done.stderr, encoding="utf-8")
    if done.returncode != 0:
        tail = (done.stdout + done.stderr).strip().splitlines()[-5:]
        raise RuntimeError(f"mutmut failed for {guard.name} (exit {done.returncode}, see {log}): " + " / ".join(tail))


def _results(guard: Guard, work: Path) -> dict[str, int]:
    """Exit code per mutant of the guard's functions (mutmut's own records)."""
    codes: dict[str, int] = {}
    wanted = [re.compile(r".*\." + re.escape(f).replace(r"\*", ".*") + r"__mutmut_\d+$") for f in guard.functions]
    for file in guard.files:
        meta = json.loads((work / "mutants" / (file + ".meta")).read_text(encoding="utf-8"))
        for key, code in meta["exit_code_by_key"].items():
            if any(w.match(key) for w in wanted):
                codes[key] = -1000 if code is None else int(code)
    return codes


def _function_start(source: str, function: str) -> int:
    """The line of a function's ``def`` (or first decorator), found from mutmut's key for it."""
    parts = function.split("ǁ")[1:] if "ǁ" in function else [function[2:]]
    tree = ast.parse(source)
    scope: list[ast.stmt] = tree.body
    for part in parts:
        for node in scope:
            if isinstance(node, ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) and node.name == part:
                if not isinstance(node, ast.ClassDef):
                    return min([node.lineno, *(d.lineno for d in node.decorator_list)])
                scope = node.body
                break
    return 1


def _functions(mutated: str) -> dict[str, str]:
    """The source of every function of a mutated module, by name (methods included)."""
    tree = ast.parse(mutated)
    found: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            found[node.name] = ast.get_source_segment(mutated, node) or ""
    return found


def _survivor(key: str, file: str, work: Path, functions: dict[str, str]) -> Survivor:
    """Where a surviving mutant is, and the lines it changed (the mutant's function against the original)."""
    name = key.rsplit(".", 1)[-1]
    function = name.split("__mutmut_")[0]
    original = functions.get(function + "__mutmut_orig", "").splitlines()
    mutant = [line.replace(name, function + "__mutmut_orig", 1) for line in functions.get(name, "").splitlines()]
    start = _function_start((work / file).read_text(encoding="utf-8"), function)
    before: list[str] = []
    after: list[str] = []
    line = start
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=original, b=mutant, autojunk=False).get_opcodes():
        if tag != "equal":
            if not before and not after:
                line = start + i1
            before += [t.strip() for t in original[i1:i2]]
            after += [t.strip() for t in mutant[j1:j2]]
    return Survivor(key, f"{file}:{line}", " ".join(before), " ".join(after))


def _pytest_mutant(guard: Guard, work: Path, key: str, timeout: float | None) -> str:
    """Run the module's whole test selection against one mutant (``""`` for none): killed, survived or timeout."""
    env = {**os.environ, "PYTHONPATH": str(work / "mutants" / "src"), "PYTHONDONTWRITEBYTECODE": "1",
           "MUTANT_UNDER_TEST": key, "PNP_MUTATION_CACHES": str(_caches(work)), "PNP_MUTATION_SEED": str(work / "seed")}
    command = [sys.executable, "-m", "pytest", "-x", "-q", "-n", "0", "-p", "no:cacheprovider", "-p", PLUGIN,
               *guard.selection]
    try:
        done = subprocess.run(command, cwd=work / "mutants", env=env, capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout"
    return "survived" if done.returncode == 0 else "killed" if done.returncode in (1, 2, 3) else "failed"


def _retested(guard: Guard, work: Path, jobs: int, codes: dict[str, int], keys: list[str],
              timeout: float) -> dict[str, int]:
    """The codes with each mutant of ``keys`` tested again against the whole of the module's test files.

    mutmut runs a mutant only against the tests it saw call the function, and it does not see a call made while
    a module- or session-scoped fixture is set up: a function only such a fixture reaches would survive untested.
    """
    def run(key: str) -> int:
        outcome = _pytest_mutant(guard, work, key, timeout)
        return {"killed": 1, "timeout": -24, "survived": 0}.get(outcome, codes[key])

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for key, code in zip(keys, pool.map(run, keys), strict=True):
            codes[key] = code
    return codes


def _record(guard: Guard, work: Path, codes: dict[str, int]) -> None:
    """The codes written back into mutmut's records, so that the next ``--again`` starts from them."""
    for file in guard.files:
        meta_path = work / "mutants" / (file + ".meta")
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        for key in meta["exit_code_by_key"]:
            if key in codes:
                meta["exit_code_by_key"][key] = codes[key]
        meta_path.write_text(json.dumps(meta, indent=4), encoding="utf-8")


def _survivors(guard: Guard, work: Path, codes: dict[str, int]) -> dict[str, Survivor]:
    """Each mutant not killed and not timed out, at its ``file:line`` with its change."""
    functions = {f: _functions((work / "mutants" / f).read_text(encoding="utf-8")) for f in guard.files}
    found: dict[str, Survivor] = {}
    for key, code in codes.items():
        if code in _KILLED or code in _TIMEOUT:
            continue
        file = next(f for f in guard.files if key.startswith(Path(f).with_suffix("").as_posix()
                                                            .removeprefix("src/").replace("/", ".") + "."))
        found[key] = _survivor(key, file, work, functions[file])
    return found


def _again(guard: Guard, work: Path, jobs: int, listed: set[str]) -> dict[str, int]:
    """The last run's survivors (listed equivalents left out) tested again with the checkout's tests, by pytest.

    mutmut is not run again: its records of the other mutants are kept as they are (a mutmut run after a change
    of the tests could reset them to "not run").
    """
    _refresh_tests(work)
    codes = _results(guard, work)
    pending = [k for k, code in codes.items() if code not in _KILLED and code not in _TIMEOUT and k not in listed]
    started = time.monotonic()
    if _pytest_mutant(guard, work, "", None) != "survived":
        raise RuntimeError(f"the tests of {guard.name} fail without a mutant: {' '.join(guard.selection)}")
    codes = _retested(guard, work, jobs, codes, pending, 3 * (time.monotonic() - started) + 10)
    _record(guard, work, codes)
    return codes


def run_guard(guard: Guard, work: Path, jobs: int, known: dict[tuple[str, str, str], str],
              again: bool = False) -> dict[str, int]:
    """Mutate one guard module (``again``: test only the last run's survivors), print its figures and survivors."""
    started = time.monotonic()

    def listed(codes: dict[str, int]) -> set[str]:
        return {k for k, s in _survivors(guard, work, codes).items() if (s.function, s.before, s.after) in known}

    if again and (work / "mutants").is_dir() and _selected_tests(work) == guard.selection:
        codes = _again(guard, work, jobs, listed(_results(guard, work)))
    else:
        _prepare(guard, work)
        _run_mutmut(guard, work, jobs)
        codes = _results(guard, work)
        equivalent = listed(codes)
        codes = _retested(guard, work, jobs, codes,
                          [k for k, c in codes.items() if c in _SURVIVED and k not in equivalent], 900)
        _record(guard, work, codes)
    survivors = _survivors(guard, work, codes)
    counts: Counter[str] = Counter(mutants=len(codes))
    counts["killed"] = sum(1 for c in codes.values() if c in _KILLED)
    counts["timeouts"] = sum(1 for c in codes.values() if c in _TIMEOUT)
    lines: list[str] = []
    for key, s in sorted(survivors.items()):
        why = known.get((s.function, s.before, s.after))
        status = "equivalent" if why is not None else _SURVIVED.get(codes[key], f"exit {codes[key]}")
        counts["equivalent" if why is not None else "survived"] += 1
        lines.append(f"  {status}: {s.where}: {s.before}  ->  {s.after}" + (f"  ({why})" if why else ""))
    seconds = time.monotonic() - started
    print(f"{guard.name}: {counts['mutants']} mutants, {counts['killed']} killed, {counts['survived']} survived, "
          f"{counts['timeouts']} timeouts, {counts['equivalent']} equivalent ({seconds:.0f} s; "
          f"{', '.join(guard.files)})", flush=True)
    for line in lines:
        print(line, flush=True)
    counts["seconds"] = round(seconds)
    return dict(counts)


def run_encoding(target: Target, work: Path, jobs: int, known: dict[tuple[str, str, str], str],
                 again: bool = False) -> dict[str, int]:
    """Mutate one ASP encoding (``again``: test only the last run's survivors), print its figures and survivors."""
    started = time.monotonic()
    results = mutation_asp.run_target(target, ROOT, work, jobs, again, known.keys())
    counts = mutation_asp.report(target, results, known, time.monotonic() - started)
    counts["seconds"] = round(time.monotonic() - started)
    return dict(counts)


def _list() -> None:
    for g in (*GUARDS, *CORE):
        print(f"{g.name}: {', '.join(g.files)}")
        print(f"  functions: {', '.join(g.functions)}\n  tests: {', '.join(g.tests)}")
        if g.deselect:
            print(f"  left out: {', '.join(g.deselect)}")
    for t in ENCODINGS:
        print(f"{t.name}: {t.file}\n  tests: {', '.join(t.tests)}")


def main(argv: list[str] | None = None) -> int:
    """Run the modules and encodings named (all by default) and print the figures; exit 1 if a mutant survived."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    parser.add_argument("modules", nargs="*", help="modules and encodings to run (default: all; see --list)")
    parser.add_argument("--list", action="store_true", help="list the modules and encodings with their files and tests")
    parser.add_argument("--jobs", type=int, default=2, help="mutants tested at once (default 2)")
    parser.add_argument("--again", action="store_true",
                        help="test only the survivors of the last run again, with the tests as they are now")
    parser.add_argument("--only", action="append", default=[], metavar="FUNCTION",
                        help="mutate only this function of the modules named (mutmut's key: x_name, xǁClassǁmethod; "
                             "* matches any text; may be given several times)")
    parser.add_argument("--work", type=Path, default=ROOT / "build" / "mutation",
                        help="folder for the per-module copies (default build/mutation)")
    args = parser.parse_args(argv)
    by_name: dict[str, Guard | Target] = {g.name: g for g in (*GUARDS, *CORE, *ENCODINGS)}
    if args.list:
        _list()
        return 0
    unknown = [m for m in args.modules if m not in by_name]
    if unknown:
        print(f"scripts/mutation.py: unknown module {unknown[0]!r}; expected one of {', '.join(by_name)}",
              file=sys.stderr)
        return 2
    if args.only and (not args.modules or any(not isinstance(by_name[m], Guard) for m in args.modules)):
        print("scripts/mutation.py: --only names functions of Python modules: name those modules, no encoding",
              file=sys.stderr)
        return 2
    known = equivalents()
    total: Counter[str] = Counter()
    try:
        for name in args.modules or list(by_name):
            unit = by_name[name]
            if args.only and isinstance(unit, Guard):
                unit = replace(unit, functions=tuple(args.only))
            run = run_guard if isinstance(unit, Guard) else run_encoding
            total.update(run(unit, args.work.resolve() / name, args.jobs, known, args.again))  # type: ignore[arg-type]
    except RuntimeError as exc:
        print(f"scripts/mutation.py: {exc}", file=sys.stderr)
        return 2
    print(f"total: {len(args.modules or by_name)} modules, {total['mutants']} mutants, {total['killed']} killed, "
          f"{total['survived']} survived, {total['timeouts']} timeouts, {total['equivalent']} equivalent "
          f"({total['seconds']} s)")
    return 1 if total["survived"] else 0


if __name__ == "__main__":
    sys.exit(main())
