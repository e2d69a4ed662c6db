"""``pnp vocab`` and ``pnp impact``: the ontology engineer's view of the loaded knowledge."""

from __future__ import annotations

import typer

from plugnproduce.cli.app import JSON_OPTION, app, boundary, emit_json, knowledge


@app.command()
@boundary
def vocab(json_out: bool = JSON_OPTION) -> None:
    """List the terms of the loaded knowledge (built-in and libraries): device classes with the skills
    they imply, skills with their mandatory states, state concepts, quantities and processes."""
    from plugnproduce.knowledge.vocab import vocabulary, vocabulary_text

    words = vocabulary(knowledge())
    if json_out:
        emit_json(words)
        return
    for line in vocabulary_text(words):
        typer.echo(line)
