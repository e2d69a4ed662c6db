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
