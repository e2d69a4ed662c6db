"""``pnp vocab`` and ``pnp impact``: the ontology engineer's view of the loaded knowledge."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from plugnproduce.cli.application import JSON_OPTION, app, boundary, emit_json, fail, knowledge
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    from plugnproduce import service
else:
    service = lazy_module("plugnproduce.service")  # `pnp --help` imports none of it

ontology_app = typer.Typer(no_args_is_help=True, rich_markup_mode=None,
                           help="The ontology of the loaded knowledge, for an ontology editor such as Protégé.")
app.add_typer(ontology_app, name="ontology")


@app.command()
@boundary
def vocab(json_out: bool = JSON_OPTION,
          tree: bool = typer.Option(False, "--tree", help="The taxonomy as an indented tree per root (devices, "
                                    "skills, state concepts, quantities, outcomes); equivalent classes on one "
                                    "line. With --json: nested nodes of names and children.")) -> None:
    """List the terms of the loaded knowledge (built-in and libraries): the roots a library's terms subclass,
    device classes with the skills they imply, skills with their mandatory states, state concepts,
    quantities, outcomes and processes; equivalent classes are marked "equivalent".

    Exit 0 listed, 2 bad input (a library that cannot be read).
    """
    from plugnproduce.service import taxonomy_tree, vocabulary, vocabulary_text, vocabulary_tree

    if tree and json_out:
        emit_json(taxonomy_tree(knowledge().taxonomy))
        return
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
    extensions: list[Path] = typer.Argument(..., metavar="EXTENSION...",
                                            help="TBox files (Turtle, RDF/XML, OWL/XML) to try on top of "
                                                 "the loaded knowledge."),
    cells: list[Path] = typer.Option([], "--cells", metavar="DIR",
                                     help="Folders (or files) of cells to compare (repeatable; "
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


@ontology_app.command("export")
@boundary
def export(
    output: Path | None = typer.Option(None, "-o", "--output", metavar="FILE",
                                       help="Write here (default: standard output)."),
    fmt: str = typer.Option("rdfxml", "--format", metavar="rdfxml|turtle|owlxml",
                            help="RDF/XML (Protégé's default), Turtle or OWL/XML."),
    inferred: bool = typer.Option(False, "--inferred", help="Add the hierarchy the reasoner (HermiT) derived as "
                                  "asserted axioms, each annotated pnp:inferredBy \"HermiT\"."),
) -> None:
    """Write the merged TBox of the loaded knowledge (the pnp ontology and every library's, imports merged in)
    as one ontology.

    Exit 0 written, 2 bad input.
    """
    from plugnproduce.service import ONTOLOGY_FORMATS as FORMATS

    if fmt not in FORMATS:
        fail(f"--format {fmt!r}: expected one of {', '.join(FORMATS)}")
    data = service.export_ontology(fmt, inferred, knowledge())
    if output is None:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
    else:
        output.write_bytes(data)
        typer.echo(f"wrote {output} ({fmt}{', with the inferred hierarchy' if inferred else ''})", err=True)
