"""``scripts/setup.sh`` installs what the README promises, says what it does, and nothing unused."""

from __future__ import annotations

import subprocess
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SETUP = ROOT / "scripts" / "setup.sh"


def test_setup_is_valid_bash() -> None:
    subprocess.run(["bash", "-n", str(SETUP)], check=True)


def test_setup_installs_no_browser_driver() -> None:
    # The browser tests drive Chromium through Playwright (DevTools protocol), not WebDriver.
    assert "chromium-driver" not in SETUP.read_text()


def test_setup_installs_what_opening_the_notebooks_needs() -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert any(d.startswith("jupyterlab") for d in extras["notebooks"])
    assert '-e ".[test,notebooks]"' in SETUP.read_text()


def test_setup_says_what_it_is_doing() -> None:
    phases = [line for line in SETUP.read_text().splitlines() if line.strip().startswith("say ")]
    assert len(phases) >= 4


def test_virtual_environments_are_not_committed() -> None:
    assert ".venv/" in (ROOT / ".gitignore").read_text().splitlines()


def test_setup_installs_ip_for_the_network_namespace_tests() -> None:
    # tests/namespaces.py makes namespaces and a veth link with 'ip' (iproute2), not on every fresh machine
    text = SETUP.read_text()
    assert "command -v ip " in text and "need+=(iproute2)" in text
