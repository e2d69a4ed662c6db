"""What a simulated device serves as its description: its own Turtle, edited as RDF (the endpoint it really
listens on, its chart named beside it), whatever way the file spells its terms."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import rdflib

from plugnproduce import service
from plugnproduce.description.loader import parse_description
from plugnproduce.ontology.vocabulary import PNP
from plugnproduce.sim.device import served_description

LIBRARY = Path(__file__).parents[1] / "data" / "libraries" / "adaptive-gripper"


def _served(turtle: str, iri: str) -> rdflib.Graph:
    graph = rdflib.Graph()
    graph.parse(data=turtle, format="turtle", publicID="file:///served/device.ttl")
    assert (rdflib.URIRef(iri), None, None) in graph
    return graph


def test_the_builtin_gripper_serves_its_real_endpoint_and_its_chart_beside_it() -> None:
    gripper = service.cell(service.builtin("cells", "bin-picking.yaml")).device("gripper")
    turtle, chart = served_description(gripper, "xirp://127.0.0.1:4711")
    graph = _served(turtle, gripper.iri)
    subject = rdflib.URIRef(gripper.iri)
    assert list(graph.objects(subject, PNP.endpoint)) == [rdflib.Literal("xirp://127.0.0.1:4711")]
    assert list(graph.objects(subject, PNP.stateChart)) == [rdflib.URIRef("file:///served/gripper.scxml")]
    assert chart == Path(gripper.chart_file).read_text(encoding="utf-8")
    original = parse_description(Path(gripper.where.file).read_bytes(), gripper.where.file).graph
    assert len(graph) == len(original)  # every other statement served as written


def test_a_library_device_spelled_its_own_way_serves_the_endpoint_it_listens_on(tmp_path: Path) -> None:
    """An endpoint written in single quotes after another subject's endpoint, a chart in another folder: the
    served description names this device's real endpoint and its chart by name."""
    device = next(d for d in service.knowledge((LIBRARY,)).devices if d.id == "adaptive-gripper")
    folder = tmp_path / "devices"
    shutil.copytree(LIBRARY / "devices", folder)
    (folder / "charts").mkdir()
    shutil.move(folder / "adaptive-gripper.scxml", folder / "charts" / "adaptive-gripper.scxml")
    text = (folder / "adaptive-gripper.ttl").read_text(encoding="utf-8")
    text = text.replace('"xirp://', "'xirp://", 1).replace(":0\" ;", ":0' ;", 1)
    text = text.replace("<adaptive-gripper.scxml>", "<charts/adaptive-gripper.scxml>")
    text += '\n<http://example.org/other-device> pnp:endpoint "xirp://127.0.0.1:1" .\n'
    (folder / "adaptive-gripper.ttl").write_text(text, encoding="utf-8")
    moved = parse_description(text.encode(), folder / "adaptive-gripper.ttl")
    assert (None, PNP.endpoint, rdflib.Literal("xirp://127.0.0.1:0")) in moved.graph  # the file as a user wrote it
    device = replace(device, where=replace(device.where, file=str(folder / "adaptive-gripper.ttl")),
                     chart_file=str(folder / "charts" / "adaptive-gripper.scxml"))
    turtle, _ = served_description(device, "xirp://127.0.0.1:4712")
    graph = _served(turtle, device.iri)
    subject = rdflib.URIRef(device.iri)
    assert list(graph.objects(subject, PNP.endpoint)) == [rdflib.Literal("xirp://127.0.0.1:4712")]
    assert list(graph.objects(subject, PNP.stateChart)) == [rdflib.URIRef("file:///served/adaptive-gripper.scxml")]
    assert list(graph.objects(rdflib.URIRef("http://example.org/other-device"), PNP.endpoint)) == \
        [rdflib.Literal("xirp://127.0.0.1:1")]
