"""The data graph: descriptions, their charts lifted to RDF, the ontology and its closure.

This is the data graph the SHACL shapes check. Each node that stands for something in
a file is indexed to its :class:`~plugnproduce.description.model.Where`, so a shape's
finding can be reported as ``file:line: message``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import rdflib
from rdflib.namespace import RDF, RDFS, XSD

from plugnproduce.description.loader import Loaded
from plugnproduce.description.model import ChartState, DeviceDescription, ProcessDescription, Task, Where
from plugnproduce.description.quantities.units import number_in
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP

NUMBERS = frozenset(str(t) for t in (XSD.decimal, XSD.double, XSD.float, XSD.integer, XSD.int, XSD.long))
"""Parameter datatypes whose values may be written as quantities with a unit."""


@dataclass
class DataGraph:
    """A data graph for the shapes, and where each of its nodes comes from."""

    graph: rdflib.Graph = field(default_factory=rdflib.Graph)
    places: dict[str, Where] = field(default_factory=dict)

    def add_tbox(self, tbox: rdflib.Graph, taxonomy: Taxonomy) -> None:
        """Add the ontology and the subsumptions the reasoner derived."""
        self.graph += tbox
        for sub, sups in taxonomy.superclasses.items():
            for sup in sups:
                if sup != sub:
                    self.graph.add((rdflib.URIRef(sub), RDFS.subClassOf, rdflib.URIRef(sup)))

    def add_description(self, loaded: Loaded) -> None:
        """Add a Turtle description as written, indexing every subject to its line."""
        self.graph += loaded.graph
        for s in set(loaded.graph.subjects()):
            if isinstance(s, rdflib.URIRef):
                self.places.setdefault(str(s), loaded.where(str(s)))
            elif str(s) not in self.places:
                self.places[str(s)] = Where(str(loaded.path))

    def add_device(self, device: DeviceDescription) -> None:
        """Lift a device's reasoned skills and its chart's states, compound ones too."""
        self.add_device_facts(device.iri, device.skills, device.chart_file, (*device.states, *device.compounds))

    def add_device_facts(self, iri: str, skills: Iterable[str], chart_file: str, states: Iterable[ChartState]) -> None:
        """Lift reasoned skills and chart states of the device ``iri``."""
        d = rdflib.URIRef(iri)
        for skill in skills:
            self.graph.add((d, PNP.hasSkill, rdflib.URIRef(skill)))
        for s in states:
            node = rdflib.URIRef(f"file://{chart_file}#{s.id}")
            self.graph.add((d, PNP.hasState, node))
            self.graph.add((node, PNP.stateId, rdflib.Literal(s.id)))
            if s.concept:
                self.graph.add((node, PNP.concept, rdflib.URIRef(s.concept)))
            self.places[str(node)] = Where(chart_file, s.line)

    def add_process(self, process: ProcessDescription) -> None:
        """Lift each role's start and end state from its chart region."""
        for role in process.roles:
            r = rdflib.URIRef(role.iri)
            self.graph.add((r, PNP.startState, rdflib.URIRef(role.start_concept)))
            self.graph.add((r, PNP.endState, rdflib.URIRef(role.end_concept)))

    def add_task(self, task: Task, processes: dict[str, ProcessDescription]) -> None:
        """Lift a task's steps and parameter values, typed as the task file gives them."""
        base = f"file://{task.file}#"
        t = rdflib.URIRef(base + "task")
        self.graph.add((t, RDF.type, PNP.Task))
        self.places[str(t)] = Where(task.file, 1)
        for step in task.steps[: len(task.steps) // task.repeat]:  # one round: repeats are alike
            node = rdflib.URIRef(f"{base}step{step.index}")
            self.places[str(node)] = task.where(step)
            self.graph.add((t, PNP.hasStep, node))
            self.graph.add((node, RDF.type, PNP.Step))
            self.graph.add((node, PNP.stepIndex, rdflib.Literal(step.index)))
            process = processes.get(step.command)
            if process is None:
                continue
            self.graph.add((node, PNP.command, rdflib.URIRef(process.iri)))
            params = {p.name: p for p in process.parameters}
            for name, value in sorted(step.values().items()):  # a link is checked by the data flow check
                if name not in params:
                    continue
                pv = rdflib.URIRef(f"{base}step{step.index}-{name}")
                self.places[str(pv)] = task.where(step, name)
                self.graph.add((node, PNP.hasValue, pv))
                self.graph.add((pv, PNP.parameter, rdflib.URIRef(params[name].iri)))
                if isinstance(value, str) and params[name].datatype in NUMBERS:  # "0.12 kN": in the parameter's unit
                    number = number_in(value, params[name].unit)
                    value = value if number is None else number
                self.graph.add((pv, PNP.value, value_literal(value)))


def value_literal(value: object) -> rdflib.Literal:
    """A task parameter value as an RDF literal, typed by what the YAML held."""
    if isinstance(value, bool):
        return rdflib.Literal(value, datatype=XSD.boolean)
    if isinstance(value, int):
        return rdflib.Literal(value, datatype=XSD.integer)
    if isinstance(value, float):
        return rdflib.Literal(repr(value), datatype=XSD.decimal)
    if isinstance(value, list) and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        return rdflib.Literal(" ".join(format(float(v), "g") for v in value), datatype=PNP.Pose)
    if isinstance(value, str):
        return rdflib.Literal(value, datatype=XSD.string)
    return rdflib.Literal(str(value), datatype=XSD.anyURI)  # a type no parameter takes
