"""``pnp vocab`` and ``pnp impact``: the ontology engineer's view of the loaded knowledge."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from plugnproduce import service
from plugnproduce.cli.app import JSON_OPTION, app, boundary, emit_json, fail, knowledge


@app.command()
@boundary
def vocab(json_out: bool = JSON_OPTION) -> None:
    """List the terms of the loaded knowledge (built-in and libraries): device classes with the skills
    they imply, skills with their mandatory states, state concepts, quantities and processes.

    Exit 0 listed, 2 bad input (a library that cannot be read).
    """
    from plugnproduce.knowledge.vocab import vocabulary, vocabulary_text

    words = vocabulary(knowledge())
    if json_out:
        emit_json(words)
        return
    for line in vocabulary_text(words):
        typer.echo(line)


@app.command()
@boundary
def impact(
    extensions: list[Path] = typer.Argument(..., metavar="EXTENSION.ttl...",
                                            help="Turtle TBox files to try on top of the loaded knowledge."),
    cells: list[Path] = typer.Option([], "--cells", metavar="DIR",
                                     help="Folders (or files) of cells to compare (repeatable; "
                                          "default: every cell of the loaded libraries)."),
    json_out: bool = JSON_OPTION,
) -> None:
    """What a TBox edit does: offered commands per cell, catalogue roles and library tasks, before and after.

    Exit 0 nothing changes, 1 something changes, 2 bad input.
    """
    for f in extensions:
        if not f.is_file():
            fail(f"{f}: no such file")
    files = [f for c in cells for f in (sorted(c.glob("*.y*ml")) if c.is_dir() else [c])] if cells else None
    result = service.impact([f.resolve() for f in extensions], files, knowledge())
    if json_out:
        emit_json(result.to_json())
    else:
        for line in impact_text(result.to_json()):
            typer.echo(line)
    if result.changed:
        raise typer.Exit(1)


def impact_text(doc: dict[str, Any]) -> list[str]:
    """An impact report as lines for a terminal."""
    if not doc["changed"]:
        return [f"no change: {', '.join(doc['extensions'])} changes no offered command, role or task"]
    lines = []
    for c in doc["cells"]:
        lines.append(f"cell {c['cell']}:" + (f" ({c['note']})" if c.get("note") else ""))
        lines += [f"  + {a['command']:<16} {' | '.join(a['bindings'])}" for a in c["added"]]
        lines += [f"  - {r['command']:<16} {' | '.join(r['bindings'])}" for r in c["removed"]]
        for ch in c["changed"]:
            lines.append(f"  ~ {ch['command']:<16} " + " ".join([*(f"+[{b}]" for b in ch["added"]),
                                                                  *(f"-[{b}]" for b in ch["removed"])]))
    for d in doc["catalogue"]:
        lines.append(f"catalogue device {d['device']}: roles " + " ".join(
            [*(f"+{r}" for r in d["roles_added"]), *(f"-{r}" for r in d["roles_removed"])]))
    for t in doc["tasks"]:
        now = "plausible" if t["plausible_after"] else "implausible"
        lines.append(f"task {t['task']} in cell {t['cell']}: now {now}")
    return lines
