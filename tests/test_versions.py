"""The environment runs the versions the project is tested with: pyproject's ranges and the lock agree,
and what is installed lies within both (a new upstream release can't slip in unnoticed)."""

from __future__ import annotations

import tomllib
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
REQUIREMENTS = {canonicalize_name(r.name): r for r in map(Requirement, [
    *PROJECT["dependencies"], *(d for extra in PROJECT["optional-dependencies"].values() for d in extra)])}


def _locked() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "scripts" / "constraints.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, _, pinned = line.partition("==")
            pins[canonicalize_name(name)] = pinned.strip()
    return pins


LOCKED = _locked()


@pytest.mark.parametrize("name", sorted(REQUIREMENTS))
def test_every_dependency_has_a_tested_range_and_a_locked_version_within_it(name: str) -> None:
    specifier = REQUIREMENTS[name].specifier
    assert any(s.operator == ">=" for s in specifier) and any(s.operator == "<" for s in specifier), \
        f"{name}: give the range tested with both bounds, not {specifier or 'none'}"
    assert name in LOCKED, f"{name} is not in scripts/constraints.txt"
    assert specifier.contains(LOCKED[name]), f"{name}: locked {LOCKED[name]} lies outside {specifier}"


@pytest.mark.parametrize("name", sorted(REQUIREMENTS))
def test_the_installed_version_is_the_tested_one(name: str) -> None:
    try:
        installed = version(name)
    except PackageNotFoundError:
        pytest.fail(f"{name} is not installed: run scripts/setup.sh")
    assert REQUIREMENTS[name].specifier.contains(installed), \
        f"{name} {installed} lies outside the tested range {REQUIREMENTS[name].specifier}"
    assert installed == LOCKED[name], f"{name} {installed} is installed, {LOCKED[name]} is the tested version"


def _imported_top_levels() -> dict[str, str]:
    """Each third-party top-level package the source imports, with one ``file:line`` that imports it."""
    import ast
    import sys

    found: dict[str, str] = {}
    src = ROOT / "src"
    for path in sorted((src / "plugnproduce").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            else:
                continue
            for top in {n.split(".")[0] for n in names} - {"plugnproduce", "__future__"}:
                if top not in sys.stdlib_module_names:
                    found.setdefault(top, f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def _declared_distributions() -> set[str]:
    """The runtime dependencies, with what their requested extras bring (``dask[distributed]`` brings
    ``distributed``)."""
    from importlib.metadata import requires

    declared = set()
    for line in PROJECT["dependencies"]:
        req = Requirement(line)
        declared.add(canonicalize_name(req.name))
        for extra in req.extras:
            for brought in map(Requirement, requires(req.name) or []):
                if brought.marker is not None and brought.marker.evaluate({"extra": extra}):
                    declared.add(canonicalize_name(brought.name))
    return declared


def test_every_third_party_import_is_a_declared_runtime_dependency() -> None:
    """A package the source imports comes from pyproject's ``dependencies`` (each with both bounds, see above),
    not merely from another package that happens to bring it today."""
    from importlib.metadata import packages_distributions

    providers, declared = packages_distributions(), _declared_distributions()
    undeclared = sorted(f"{where}: {top} (from {', '.join(providers.get(top, ['no installed distribution']))})"
                        for top, where in _imported_top_levels().items()
                        if not {canonicalize_name(d) for d in providers.get(top, [])} & declared)
    assert undeclared == [], "imported but not declared in pyproject's dependencies: " + "; ".join(undeclared)
