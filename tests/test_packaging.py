"""Data folders ship in the wheel and are found from an editable install."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

from plugnproduce.resources import data_path, descriptions_path, ontology_path, rules_path


def test_data_folders_are_found() -> None:
    assert (ontology_path() / "pnp.ttl").is_file()
    assert (ontology_path() / "shapes.ttl").is_file()
    assert (descriptions_path() / "cells" / "bin-picking.yaml").is_file()
    assert rules_path().is_dir()
    assert data_path("rules") == rules_path()


def test_wheel_ships_the_data_folders(tmp_path: Path) -> None:
    root = Path(__file__).resolve().parents[1]
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(tmp_path), str(root)],
        check=True,
        capture_output=True,
    )
    wheel = next(tmp_path.glob("plugnproduce-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for needed in (
        "plugnproduce/data/ontology/pnp.ttl",
        "plugnproduce/data/ontology/closure.json",
        "plugnproduce/data/ontology/shapes.ttl",
        "plugnproduce/data/descriptions/cells/bin-picking.yaml",
        "plugnproduce/data/descriptions/devices/gripper.scxml",
        "plugnproduce/statechart/io/w3c/scxml.xsd",
        "plugnproduce/py.typed",
    ):
        assert needed in names, needed
