"""Description files → :mod:`plugnproduce.description.model` objects.

Every error names the file and line. The RDF graph each description came from is
kept (:class:`Loaded`) so the SHACL shapes can check the same data.
"""

from __future__ import annotations

import keyword
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from urllib.parse import unquote, urlparse

import rdflib
import yaml
from rdflib.namespace import RDF, RDFS, XSD

from plugnproduce.description.charts import device_chart, process_regions
from plugnproduce.description.model import (
    Argument,
    Cell,
    ChartTransition,
    DeviceDescription,
    Output,
    Parameter,
    ProcessDescription,
    Role,
    Where,
)
from plugnproduce.description.ranges import output_ranges
from plugnproduce.description.rdf import term_line
from plugnproduce.description.taskfile import _mapping, _plain, _unknown_keys
from plugnproduce.description.taskfile import load_task as load_task
from plugnproduce.description.taskfile import parse_task as parse_task
from plugnproduce.description.taskfile import task_to_yaml as task_to_yaml
from plugnproduce.description.units import unit_known
from plugnproduce.errors import DescriptionError, UnreadableError, excerpt
from plugnproduce.ontology.names import turtle_spelling, unknown_class
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.safeio import (
    parse_turtle,
    parse_turtle_bytes,
    parse_yaml_node,
)
from plugnproduce.statechart.io.reader import parse_chart, read_chart

SAFE_STOP = str(PNP.SafeStop)
"""A device state chart's transition annotated with this concept (or one below it) is its safe-stop request."""

PROTOCOL_NAMES = {str(PNP.XIRP): "xirp", str(PNP.UPnP): "upnp", str(PNP.OPCUA): "opcua"}
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")
_OUTPUT_NAME = re.compile(r"[a-z][a-z0-9_]{0,63}")


class ContractError(DescriptionError):
    """A device's argument contract that does not fit its chart, or names a unit there is not."""


@dataclass(frozen=True)
class Loaded:
    """A parsed Turtle description: its graph, text and path."""

    path: Path
    graph: rdflib.Graph
    text: str

    def line(self, iri: str) -> int | None:
        """The line where ``iri`` is described in the file."""
        return term_line(self.text, self.graph, iri)

    def where(self, iri: str) -> Where:
        """The place where ``iri`` is described."""
        return Where(str(self.path), self.line(iri))


def read_description(path: str | Path) -> Loaded:
    """Parse a Turtle description file."""
    p = Path(path)
    g, text = parse_turtle(p)
    return Loaded(p, g, text)


def parse_description(data: bytes, path: str | Path) -> Loaded:
    """Parse a Turtle description from bytes as if it were the file at ``path`` (relative IRIs resolve
    against it, messages name it); nothing is read from disk."""
    p = Path(path)
    g, text = parse_turtle_bytes(data, p)
    return Loaded(p, g, text)


def _one(loaded: Loaded, subject: rdflib.term.Node, prop: rdflib.URIRef, what: str) -> rdflib.term.Node:
    values = list(loaded.graph.objects(subject, prop))
    if len(values) != 1:
        found = "none" if not values else f"{len(values)} values"
        raise DescriptionError(
            f"{local_name(str(subject))} needs exactly one {what} ({local_name(str(prop))}); found {found}",
            loaded.path,
            loaded.line(str(subject)),
        )
    return values[0]


def _opt(loaded: Loaded, subject: rdflib.term.Node, prop: rdflib.URIRef) -> rdflib.term.Node | None:
    return next(iter(loaded.graph.objects(subject, prop)), None)


def file_of(iri: rdflib.term.Node) -> Path:
    """The local path a ``file:`` IRI (a relative reference in a description) names."""
    return Path(unquote(urlparse(str(iri)).path))


def device_subject(loaded: Loaded, taxonomy: Taxonomy) -> rdflib.URIRef:
    """The one device a device description describes."""
    devices = sorted(
        {s for s, c in loaded.graph.subject_objects(RDF.type) if isinstance(s, rdflib.URIRef)
         and taxonomy.is_kind(str(c), "Device")}
    )
    if not devices:
        _unknown_device_class(loaded, taxonomy)
    if len(devices) != 1:
        raise DescriptionError(
            f"a device description describes exactly one device (an individual of a pnp:Device class); "
            f"found {len(devices)}",
            loaded.path,
            1,
        )
    return devices[0]


def _unknown_device_class(loaded: Loaded, taxonomy: Taxonomy) -> None:
    """A would-be device (it has a state chart) whose class is unknown: say so at its line."""
    spell = turtle_spelling(loaded.graph.namespace_manager)
    for s in sorted(set(loaded.graph.subjects(PNP.stateChart)), key=str):
        for c in sorted(loaded.graph.objects(s, RDF.type), key=str):
            if not taxonomy.knows(str(c)):
                raise DescriptionError(unknown_class(str(s), str(c), taxonomy, spell), loaded.path,
                                       loaded.line(str(s)))


def device_from(loaded: Loaded, taxonomy: Taxonomy, charts: Mapping[Path, bytes] | None = None) -> DeviceDescription:
    """Build the device of a parsed description, with its chart and reasoned skills.

    The chart is read from the file its ``pnp:stateChart`` names or, given ``charts`` (SCXML by path,
    e.g. the files a device serves), taken from there only: a chart not among them is an error.
    """
    s = device_subject(loaded, taxonomy)
    classes = tuple(sorted(str(c) for c in loaded.graph.objects(s, RDF.type) if taxonomy.is_kind(str(c), "Device")))
    declared = tuple(sorted(str(k) for k in loaded.graph.objects(s, PNP.hasSkill)))
    protocol = str(_one(loaded, s, PNP.protocol, "protocol"))
    if protocol not in PROTOCOL_NAMES:
        raise DescriptionError(
            f"unknown protocol {local_name(protocol)}; expected pnp:XIRP, pnp:UPnP or pnp:OPCUA", loaded.path,
            loaded.line(str(s))
        )
    chart_file = file_of(_one(loaded, s, PNP.stateChart, "state chart"))
    if charts is None:
        chart = read_chart(chart_file)
    elif chart_file in charts:
        chart = parse_chart(charts[chart_file], chart_file)
    else:
        raise DescriptionError(f"{local_name(str(s))} names chart {chart_file.name}; expected one of "
                               f"{', '.join(sorted(c.name for c in charts)) or 'none'}",
                               loaded.path, loaded.line(str(s)))
    lifted = device_chart(chart, chart_file)
    every = lifted.transitions
    stops = tuple(t for t in every if t.concept is not None and taxonomy.is_a(t.concept, SAFE_STOP))
    transitions = tuple(t for t in every if t not in stops)
    timeout = _opt(loaded, s, PNP.commandTimeout)
    cost = _opt(loaded, s, PNP.cost)
    label = _opt(loaded, s, RDFS.label)
    arguments = tuple(sorted((_argument(loaded, a) for a in loaded.graph.objects(s, PNP.hasArgument)),
                             key=lambda a: (a.request, a.quantity)))
    _check_arguments(arguments, transitions, loaded.path)
    device = DeviceDescription(
        id=local_name(str(s)),
        iri=str(s),
        label=str(label) if label is not None else local_name(str(s)),
        classes=classes,
        declared_skills=declared,
        protocol=PROTOCOL_NAMES[protocol],
        endpoint=str(_one(loaded, s, PNP.endpoint, "endpoint")),
        chart_file=str(chart_file),
        initial=lifted.initial,
        states=lifted.states,
        transitions=transitions,
        compounds=lifted.compounds,
        where=loaded.where(str(s)),
        command_timeout=_or(_finite(loaded, s, timeout, "command timeout"), 10.0),
        cost=_or(_finite(loaded, s, cost, "cost"), 0.0),
        skills=tuple(sorted(taxonomy.device_skills(classes, declared))),
        chart=chart,
        stops=stops,
        arguments=arguments,
    )
    try:  # a range its chart declares for a value it reports is a number, at its line
        output_ranges(device)
    except DescriptionError as exc:
        raise ContractError(exc.message, exc.file, exc.line) from None
    return device


def _check_arguments(arguments: tuple[Argument, ...], transitions: tuple[ChartTransition, ...], path: Path) -> None:
    """Each argument belongs to a request of the chart that accepts its quantity, in a unit there is."""
    accepted = {(t.request.name, q) for t in transitions if t.request for q in t.accepts}
    for a in arguments:
        line = a.where.line if a.where else None
        quantity, request = excerpt(local_name(a.quantity)), excerpt(a.request)  # as the file spells them: short
        if (a.request, a.quantity) not in accepted:
            raise ContractError(f"argument {quantity} of request {request}: no transition of the "
                                   f"chart waits for request {request} with pnp:accepts=\"{quantity}\"",
                                   path, line)
        if not unit_known(a.unit):
            raise ContractError(f"argument {quantity} of request {request}: unknown unit "
                                   f"{excerpt(a.unit)!r}; expected a unit such as \"N\", \"mm/s\" or \"kPa\"",
                                   path, line)


def _argument(loaded: Loaded, a: rdflib.term.Node) -> Argument:
    """One ``pnp:RequestArgument`` of a device (the shapes check its terms; the limits must be finite)."""
    required = _opt(loaded, a, PNP.required)
    datatype = _opt(loaded, a, PNP.datatype)
    return Argument(
        request=str(_one(loaded, a, PNP.request, "request")),
        quantity=str(_one(loaded, a, PNP.quantity, "quantity")),
        required=not (isinstance(required, rdflib.Literal) and required.toPython() is False),
        datatype=str(datatype) if datatype is not None else "",
        unit=str(_opt(loaded, a, PNP.unit) or ""),
        minimum=_finite(loaded, a, _opt(loaded, a, PNP.minValue), "minimum"),
        maximum=_finite(loaded, a, _opt(loaded, a, PNP.maxValue), "maximum"),
        reach=_finite(loaded, a, _opt(loaded, a, PNP.maxReach), "maximum reach"),
        default=_default(_opt(loaded, a, PNP.defaultValue)),
        where=loaded.where(str(a)),
    )


def load_device(path: str | Path, taxonomy: Taxonomy) -> DeviceDescription:
    """Read a device description (Turtle + its Device State Chart)."""
    return device_from(read_description(path), taxonomy)


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
    chart_file = file_of(_one(loaded, s, PNP.generalChart, "general process state chart"))
    chart = read_chart(chart_file)
    regions = process_regions(chart, chart_file)
    roles: list[Role] = []
    for r in sorted(loaded.graph.objects(s, PNP.hasRole), key=str):
        name = str(_one(loaded, r, PNP.roleName, "role name"))
        if name not in regions:
            raise DescriptionError(
                f"role {name!r} has no region in {chart_file.name}; expected a region with pnp:role=\"{name}\"",
                loaded.path,
                loaded.line(str(r)),
            )
        skill = str(_one(loaded, r, PNP.requiresSkill, "required skill"))
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
    label = _opt(loaded, s, RDFS.label)
    comment = _opt(loaded, s, RDFS.comment)
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


def _finite(loaded: Loaded, subject: rdflib.term.Node, node: rdflib.term.Node | None, what: str) -> float | None:
    """A literal read as a finite number (None if absent); an ill-typed, huge or NaN one is refused at its line."""
    if not isinstance(node, rdflib.Literal):
        return None
    try:
        value = float(node.toPython())
    except (TypeError, ValueError, OverflowError):
        value = math.nan
    if not math.isfinite(value):
        raise UnreadableError(f"{local_name(str(subject))}: {what} {excerpt(str(node))!r} is not a finite number; "
                              "expected a decimal such as 2.5", loaded.path, loaded.line(str(subject)))
    return value


def _or(value: float | None, default: float) -> float:
    return default if value is None else value


def _default(node: rdflib.term.Node | None) -> object:
    """A default value as a plain Python value (a decimal as a float, never ``Decimal``)."""
    if not isinstance(node, rdflib.Literal):
        return None
    value = node.toPython()
    return float(value) if isinstance(value, Decimal) else value


def _parameter(loaded: Loaded, p: rdflib.term.Node) -> Parameter:
    role = _one(loaded, p, PNP.forRole, "role")
    role_name = _opt(loaded, role, PNP.roleName)
    default = _opt(loaded, p, PNP.defaultValue)
    return Parameter(
        name=str(_one(loaded, p, PNP.parameterName, "parameter name")),
        iri=str(p),
        role=str(role_name) if role_name is not None else local_name(str(role)),
        quantity=str(_one(loaded, p, PNP.quantity, "quantity")),
        datatype=str(_one(loaded, p, PNP.datatype, "datatype")),
        unit=str(_opt(loaded, p, PNP.unit) or ""),
        minimum=_finite(loaded, p, _opt(loaded, p, PNP.minValue), "minimum"),
        maximum=_finite(loaded, p, _opt(loaded, p, PNP.maxValue), "maximum"),
        default=_default(default),
        where=loaded.where(str(p)),
    )


def _output(loaded: Loaded, o: rdflib.term.Node) -> Output:
    role = _one(loaded, o, PNP.forRole, "role")
    role_name = _opt(loaded, role, PNP.roleName)
    name = str(_one(loaded, o, PNP.outputName, "output name"))
    if not _OUTPUT_NAME.fullmatch(name) or keyword.iskeyword(name):
        raise DescriptionError(f"output name {excerpt(repr(name))} must be a lower_snake_case name such as part_pose",
                               loaded.path, loaded.line(str(o)))
    return Output(
        name=name,
        iri=str(o),
        role=str(role_name) if role_name is not None else local_name(str(role)),
        quantity=str(_one(loaded, o, PNP.quantity, "quantity")),
        datatype=str(_one(loaded, o, PNP.datatype, "datatype")),
        unit=str(_opt(loaded, o, PNP.unit) or ""),
        where=loaded.where(str(o)),
    )


def load_process(path: str | Path) -> ProcessDescription:
    """Read a process description (Turtle + its General Process State Chart)."""
    return process_from(read_description(path))


# ------------------------------------------------------------------ YAML: cells (tasks: taskfile.py)


def cell_device_files(path: str | Path) -> tuple[str, list[tuple[Path, int]]]:
    """A cell file's name and its device description files with the lines that list them."""
    p = Path(path)
    top = _mapping(parse_yaml_node(p), p, "cell")
    _unknown_keys(top, {"cell", "devices", "libraries"}, p, "cell")
    if "cell" not in top or "devices" not in top or not isinstance(top["devices"], yaml.SequenceNode):
        raise DescriptionError("a cell needs 'cell' (its name) and 'devices' (a list of files)", p, 1)
    files = []
    for node in top["devices"].value:
        if not isinstance(node, yaml.ScalarNode):
            raise DescriptionError("each device is a path to a device description", p, node.start_mark.line + 1)
        files.append((_device_path(p, node), node.start_mark.line + 1))
    return str(_plain(top["cell"])), files


def cell_libraries(path: str | Path) -> list[Path]:
    """The library folders a cell file lists under ``libraries:`` (relative to the cell file)."""
    p = Path(path)
    top = _mapping(parse_yaml_node(p), p, "cell")
    node = top.get("libraries")
    if node is None:
        return []
    if not isinstance(node, yaml.SequenceNode) or not all(isinstance(n, yaml.ScalarNode) for n in node.value):
        raise DescriptionError("libraries must be a list of folders (relative to the cell file)", p,
                               node.start_mark.line + 1)
    out = []
    for n in node.value:
        folder = (p.parent / n.value).resolve()
        if not folder.is_dir():
            raise DescriptionError(f"library folder {excerpt(n.value)} not found", p, n.start_mark.line + 1)
        out.append(folder)
    return out


MAX_PATH = 1024
"""Longest device path a cell may list (file systems refuse names much longer than 255 bytes anyway)."""


def _device_path(cell: Path, node: yaml.ScalarNode) -> Path:
    """A device path a cell lists, resolved beside the cell; one no file system could hold is refused."""
    value = str(node.value)
    parts = value.replace("\\", "/").split("/")
    if "\0" in value or len(value) > MAX_PATH or any(len(part.encode("utf-8", "replace")) > 255 for part in parts):
        raise DescriptionError(f"device path {excerpt(value)!r} ({len(value)} characters) cannot name a file; "
                               "expected a path to a device description", cell, node.start_mark.line + 1)
    return (cell.parent / value).resolve()


def not_a_description(entry: Path) -> str | None:
    """Why a file a cell lists is no device description (a device description is a Turtle ``.ttl`` file), or None.

    Nothing of the file is read, so nothing of it (``/etc/passwd``) is ever quoted.
    """
    if entry.suffix.lower() == ".ttl" or not entry.is_file():
        return None
    return (f"device entry {excerpt(entry.name)!r} is a file that is no device description; expected a "
            "Turtle file (.ttl) or the id of a device of a loaded library")


def load_cell(path: str | Path, taxonomy: Taxonomy,
              by_id: Callable[[str], DeviceDescription | None] | None = None) -> Cell:
    """Read a cell (YAML) and all its device descriptions.

    An entry that is no file but a plain id (``robot``) names a catalogue device, found by ``by_id``.
    """
    name, files = cell_device_files(path)
    devices = []
    for f, line in files:
        if (why := not_a_description(f)) is not None:
            raise DescriptionError(why, path, line)
        if f.is_file():
            devices.append(load_device(f, taxonomy))
            continue
        known = by_id(f.name) if by_id is not None and f.suffix != ".ttl" else None
        if known is None:
            raise DescriptionError(f"device description {excerpt(f.name)} not found; expected a device description "
                                   "file (relative to the cell file) or the id of a device of a loaded library",
                                   path, line)
        devices.append(known)
    ids = [d.id for d in devices]
    for d in devices:
        if ids.count(d.id) > 1:
            raise DescriptionError(f"device id {excerpt(d.id)!r} appears twice in the cell", path)
    return Cell(name, tuple(devices), str(path))


def load_devices(folder: str | Path, taxonomy: Taxonomy) -> list[DeviceDescription]:
    """Every device description in a folder (a catalogue), sorted by id."""
    return sorted((load_device(f, taxonomy) for f in sorted(Path(folder).glob("*.ttl"))), key=lambda d: d.id)


def load_processes(folder: str | Path) -> list[ProcessDescription]:
    """Every process description in a folder, sorted by command name."""
    return sorted((load_process(f) for f in sorted(Path(folder).glob("*.ttl"))), key=lambda p: p.id)


POSE_DATATYPE = str(PNP.Pose)
NUMERIC = {str(XSD.decimal), str(XSD.integer), str(XSD.double), str(XSD.float)}
