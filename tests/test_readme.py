"""The README: its two commands first, then a tour whose links all lead somewhere."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_the_two_commands_come_first() -> None:
    block = re.search(r"```bash\n(.*?)```", README, re.S)
    assert block is not None and README.index("```bash") < README.index("\n## ")
    assert block.group(1).splitlines() == [
        "bash scripts/setup.sh && pnp capabilities --cell descriptions/cells/bin-picking.yaml"
        " && pnp run descriptions/tasks/bin-picking.yaml --sim",
        "python -m pytest",
    ]


def test_every_link_leads_to_a_file() -> None:
    links = re.findall(r"\]\(([^)#]+)\)", README)
    assert links
    assert [link for link in links if not (ROOT / link).exists()] == []


def test_the_tour_links_every_notebook() -> None:
    for notebook in (ROOT / "notebooks").glob("*.ipynb"):
        assert f"(notebooks/{notebook.name})" in README, notebook.name
