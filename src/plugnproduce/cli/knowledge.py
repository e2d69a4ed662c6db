"""``pnp vocab`` and ``pnp impact``: the ontology engineer's view of the loaded knowledge."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from plugnproduce import service
from plugnproduce.cli.app import JSON_OPTION, app, boundary, emit_json, fail, knowledge


@app.command()
@boundary
def vocab(json_out: bool = JSON_OPTION,
          tree: bool = typer.Option(False, "--tree", help="The taxonomy as an indented tree per root (devices, "
                                    "skills, state concepts, quantities, outcomes); equivalent classes on one "
                                    "line.")) -> None:
    """List the terms of the loaded knowledge (built-in and libraries): the roots a library's terms subclass,
    device classes with the skills they imply, skills with their mandatory states, state concepts,
    quantities, outcomes and processes; equivalent classes are marked "equivalent"."""
    from plugnproduce.knowledge.vocab import vocabulary, vocabulary_text, vocabulary_tree

    if tree:
        for line in vocabulary_tree(knowledge().taxonomy):
            typer.echo(line)
        return
    words = vocabulary(knowledge())
    if json_out:
        emit_json(words)
        return
    for line in vocabulary_text(words):
        typer.echo(line)


@app.command()
@boundary
def impact(
    extensions: list[Path] = typer.Argument(..., help="TBox files (Turtle, RDF/XML, OWL/XML) to try on top of "
                                            "the loaded knowledge."),
    cells: list[Path] = typer.Option([], "--cells", help="Folders (or files) of cells to compare (repeatable; "
                                     "default: every cell of the loaded libraries)."),
    json_out: bool = JSON_OPTION,
) -> None:
    """What a TBox edit does: offered commands per cell, catalogue roles, library tasks and the validation
    findings (SHACL shapes, structure) of every catalogue device and cell, before and after.

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
        return [f"no change: {', '.join(doc['extensions'])} changes no offered command, role, task or validation "
                "finding"]
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
    for word, key in (("new violation", "new_violations"), ("cured violation", "cured_violations")):
        for v in doc.get(key, []):
            where = f"{v['file']}:{v['line']}" if v["line"] else v["file"]
            lines.append(f"{word}: {where}: {v['message']}")
    return lines
