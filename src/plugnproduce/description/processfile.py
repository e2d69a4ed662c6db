"""Process descriptions (Turtle + a General Process State Chart) →
:class:`~plugnproduce.description.model.ProcessDescription`.

Every error names the file and line.
"""

from __future__ import annotations

import keyword
import re
from pathlib import Path

import rdflib
from rdflib.namespace import RDF, RDFS

from plugnproduce.description.charts import process_regions
from plugnproduce.description.model import Output, Parameter, ProcessDescription, Role
from plugnproduce.description.quantities.units import no_pose_unit
from plugnproduce.description.rdf import (
    Loaded,
    file_of,
    finite_number,
    one_value,
    optional_value,
    plain_default,
    read_description,
)
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.statechart.io.reader import read_chart

_OUTPUT_NAME = re.compile(r"[a-z][a-z0-9_]{0,63}")


def process_from(loaded: Loaded) -> ProcessDescription:
    """Build the process of a parsed description, with its chart's regions."""
    subjects = sorted({s for s in loaded.graph.subjects(PNP.generalChart) if isinstance(s, rdflib.URIRef)})
    if len(subjects) != 1:
        raise DescriptionError(
            f"a process description describes exactly one process (with pnp:generalChart); found {len(subjects)}",
            loaded.path,
            1,
        )
    s = subjects[0]
    chart_file = file_of(one_value(loaded, s, PNP.generalChart, "general process state chart"))
    chart = read_chart(chart_file)
    regions = process_regions(chart, chart_file)
    roles: list[Role] = []
    for r in sorted(loaded.graph.objects(s, PNP.hasRole), key=str):
        name = str(one_value(loaded, r, PNP.roleName, "role name"))
        if name not in regions:
            raise DescriptionError(
                f"role {name!r} has no region in {chart_file.name}; expected a region with pnp:role=\"{name}\"",
                loaded.path,
                loaded.line(str(r)),
            )
        skill = str(one_value(loaded, r, PNP.requiresSkill, "required skill"))
        roles.append(Role(name, str(r), skill, regions[name], loaded.where(str(r))))
    missing = sorted(set(regions) - {r.name for r in roles})
    if missing:
        raise DescriptionError(
            f"chart region(s) {', '.join(missing)} have no pnp:Role in the metadata", loaded.path, loaded.line(str(s))
        )
    params = tuple(
        sorted((_parameter(loaded, p) for p in loaded.graph.objects(s, PNP.hasParameter)), key=lambda p: p.name)
    )
    outputs = tuple(sorted((_output(loaded, o) for o in loaded.graph.objects(s, PNP.hasOutput)), key=lambda o: o.name))
    label = optional_value(loaded, s, RDFS.label)
    comment = optional_value(loaded, s, RDFS.comment)
    return ProcessDescription(
        id=local_name(str(s)),
        iri=str(s),
        label=str(label) if label is not None else local_name(str(s)),
        comment=str(comment) if comment is not None else "",
        classes=tuple(sorted(str(c) for c in loaded.graph.objects(s, RDF.type))),
        roles=tuple(sorted(roles, key=lambda r: r.name)),
        parameters=params,
        chart_file=str(chart_file),
        where=loaded.where(str(s)),
        chart=chart,
        outputs=outputs,
    )


def _pose_unit(loaded: Loaded, node: rdflib.term.Node, what: str) -> None:
    """A pose's unit is a pose unit (a length and an angle), or there is none."""
    datatype, unit = optional_value(loaded, node, PNP.datatype), optional_value(loaded, node, PNP.unit)
    wrong = no_pose_unit(str(unit or "")) if str(datatype) == PNP_IRI + "Pose" else None
    if wrong is not None:
        raise DescriptionError(f"{what}: {wrong}", loaded.path, loaded.line(str(node)))


def _parameter(loaded: Loaded, p: rdflib.term.Node) -> Parameter:
    _pose_unit(loaded, p, f"parameter {excerpt(str(optional_value(loaded, p, PNP.parameterName)))}")
    role = one_value(loaded, p, PNP.forRole, "role")
    role_name = optional_value(loaded, role, PNP.roleName)
    default = optional_value(loaded, p, PNP.defaultValue)
    return Parameter(
        name=str(one_value(loaded, p, PNP.parameterName, "parameter name")),
        iri=str(p),
        role=str(role_name) if role_name is not None else local_name(str(role)),
        quantity=str(one_value(loaded, p, PNP.quantity, "quantity")),
        datatype=str(one_value(loaded, p, PNP.datatype, "datatype")),
        unit=str(optional_value(loaded, p, PNP.unit) or ""),
        minimum=finite_number(loaded, p, optional_value(loaded, p, PNP.minValue), "minimum"),
        maximum=finite_number(loaded, p, optional_value(loaded, p, PNP.maxValue), "maximum"),
        default=plain_default(default),
        where=loaded.where(str(p)),
    )


def _output(loaded: Loaded, o: rdflib.term.Node) -> Output:
    _pose_unit(loaded, o, f"output {excerpt(str(optional_value(loaded, o, PNP.outputName)))}")
    role = one_value(loaded, o, PNP.forRole, "role")
    role_name = optional_value(loaded, role, PNP.roleName)
    name = str(one_value(loaded, o, PNP.outputName, "output name"))
    if not _OUTPUT_NAME.fullmatch(name) or keyword.iskeyword(name):
        raise DescriptionError(f"output name {excerpt(repr(name))} must be a lower_snake_case name such as part_pose",
                               loaded.path, loaded.line(str(o)))
    return Output(
        name=name,
        iri=str(o),
        role=str(role_name) if role_name is not None else local_name(str(role)),
        quantity=str(one_value(loaded, o, PNP.quantity, "quantity")),
        datatype=str(one_value(loaded, o, PNP.datatype, "datatype")),
        unit=str(optional_value(loaded, o, PNP.unit) or ""),
        where=loaded.where(str(o)),
    )


def load_process(path: str | Path) -> ProcessDescription:
    """Read a process description (Turtle + its General Process State Chart)."""
    return process_from(read_description(path))
