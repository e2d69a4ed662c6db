"""A cell file entry that is no device description is refused without a word of its content."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from plugnproduce.cli import app

SECRET = "root:x:0:0:secret-word:/root:/bin/bash\n"


@pytest.fixture
def cell(tmp_path: Path) -> Path:
    (tmp_path / "passwd").write_text(SECRET)
    path = tmp_path / "cell.yaml"
    path.write_text("cell: evil\ndevices:\n  - passwd\n")
    return path


@pytest.mark.parametrize("command, code", [(["validate"], 1), (["capabilities", "--cell"], 2)])
def test_issue_24_a_file_that_is_no_description_is_refused_without_echoing_it(
        cell: Path, command: list[str], code: int) -> None:
    # pnp validate said the cell was valid, and pnp capabilities quoted the file's first line
    result = CliRunner().invoke(app, [*command, str(cell)])
    assert result.exit_code == code
    said = result.stdout + result.stderr
    assert f"{cell}:3: device entry 'passwd' is a file that is no device description" in said
    assert "root" not in said.replace(str(cell.parent), "") and "secret-word" not in said
    assert len(said.strip().splitlines()) == 1
