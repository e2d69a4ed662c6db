"""Description files → :mod:`plugnproduce.description.model` objects: devices and cells here, processes in
:mod:`~plugnproduce.description.processfile`, tasks in :mod:`~plugnproduce.description.taskfile` (all named
here).

Every error names the file and line. The RDF graph each description came from is
kept (:class:`~plugnproduce.description.rdf.Loaded`) so the SHACL shapes can check the same data.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import rdflib
from rdflib.namespace import RDF, RDFS, XSD

from plugnproduce.description.cellfile import MAX_PATH as MAX_PATH
from plugnproduce.description.cellfile import cell_device_files as cell_device_files
from plugnproduce.description.cellfile import cell_libraries as cell_libraries
from plugnproduce.description.cellfile import load_cell as load_cell
from plugnproduce.description.cellfile import not_a_description as not_a_description
from plugnproduce.description.charts import device_chart
from plugnproduce.description.model import (
    Argument,
    ChartTransition,
    DeviceDescription,
    ProcessDescription,
)
from plugnproduce.description.processfile import load_process as load_process
from plugnproduce.description.processfile import process_from as process_from
from plugnproduce.description.quantities.durations import RequestDuration
from plugnproduce.description.quantities.ranges import output_ranges
from plugnproduce.description.quantities.units import no_pose_unit, unit_known
from plugnproduce.description.rdf import Loaded as Loaded
from plugnproduce.description.rdf import file_of as file_of
from plugnproduce.description.rdf import (
    finite_number,
    one_value,
    optional_value,
    or_default,
    plain_default,
)
from plugnproduce.description.rdf import parse_description as parse_description
from plugnproduce.description.rdf import read_description as read_description
from plugnproduce.description.taskfile import load_task as load_task
from plugnproduce.description.taskfile import parse_task as parse_task
from plugnproduce.description.taskfile import task_to_yaml as task_to_yaml
from plugnproduce.errors import DescriptionError, excerpt
from plugnproduce.ontology.iris import PNP_IRI
from plugnproduce.ontology.names import turtle_spelling, unknown_class
from plugnproduce.ontology.taxonomy import Taxonomy
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.statechart.io.reader import parse_chart, read_chart

SAFE_STOP = str(PNP.SafeStop)
"""A device state chart's transition annotated with this concept (or one below it) is its safe-stop request."""

PROTOCOL_NAMES = {str(PNP.XIRP): "xirp", str(PNP.UPnP): "upnp", str(PNP.OPCUA): "opcua"}
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")


class ContractError(DescriptionError):
    """A device's argument contract that does not fit its chart, or names a unit there is not."""


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
    protocol = str(one_value(loaded, s, PNP.protocol, "protocol"))
    if protocol not in PROTOCOL_NAMES:
        raise DescriptionError(
            f"unknown protocol {local_name(protocol)}; expected pnp:XIRP, pnp:UPnP or pnp:OPCUA", loaded.path,
            loaded.line(str(s))
        )
    chart_file = file_of(one_value(loaded, s, PNP.stateChart, "state chart"))
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
    timeout = optional_value(loaded, s, PNP.commandTimeout)
    cost = optional_value(loaded, s, PNP.cost)
    label = optional_value(loaded, s, RDFS.label)
    arguments = tuple(sorted((_argument(loaded, a) for a in loaded.graph.objects(s, PNP.hasArgument)),
                             key=lambda a: (a.request, a.quantity)))
    _check_arguments(arguments, transitions, loaded.path)
    durations = tuple(sorted((_duration(loaded, d) for d in loaded.graph.objects(s, PNP.hasDuration)),
                             key=lambda d: d.request))
    _check_durations(durations, transitions, loaded.path)
    device = DeviceDescription(
        id=local_name(str(s)),
        iri=str(s),
        label=str(label) if label is not None else local_name(str(s)),
        classes=classes,
        declared_skills=declared,
        protocol=PROTOCOL_NAMES[protocol],
        endpoint=str(one_value(loaded, s, PNP.endpoint, "endpoint")),
        chart_file=str(chart_file),
        initial=lifted.initial,
        states=lifted.states,
        transitions=transitions,
        compounds=lifted.compounds,
        where=loaded.where(str(s)),
        command_timeout=or_default(finite_number(loaded, s, timeout, "command timeout"), 10.0),
        cost=or_default(finite_number(loaded, s, cost, "cost"), 0.0),
        skills=tuple(sorted(taxonomy.device_skills(classes, declared))),
        chart=chart,
        stops=stops,
        arguments=arguments,
        durations=durations,
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
        if a.datatype == PNP_IRI + "Pose" and (wrong := no_pose_unit(a.unit)) is not None:
            raise ContractError(f"argument {quantity} of request {request}: {wrong}", path, line)
        if not unit_known(a.unit):
            raise ContractError(f"argument {quantity} of request {request}: unknown unit "
                                   f"{excerpt(a.unit)!r}; expected a unit such as \"N\", \"mm/s\" or \"kPa\"",
                                   path, line)


def _duration(loaded: Loaded, d: rdflib.term.Node) -> RequestDuration:
    """One ``pnp:hasDuration`` of a device (the shapes check its terms; the numbers must be finite)."""
    motion, share = optional_value(loaded, d, PNP.motionOf), optional_value(loaded, d, PNP.speedShare)
    return RequestDuration(
        request=str(one_value(loaded, d, PNP.forRequest, "request")),
        seconds=finite_number(loaded, d, optional_value(loaded, d, PNP.seconds), "duration"),
        motion_of=str(motion) if motion is not None else None,
        top_speed=finite_number(loaded, d, optional_value(loaded, d, PNP.topSpeed), "top speed"),
        speed_share=str(share) if share is not None else None,
        where=loaded.where(str(d)),
    )


def _check_durations(durations: tuple[RequestDuration, ...], transitions: tuple[ChartTransition, ...],
                     path: Path) -> None:
    """Each duration belongs to a request of the chart, once, and a motion to a quantity the request takes."""
    accepts = {t.request.name: set(t.accepts) for t in transitions if t.request}
    seen: set[str] = set()
    for d in durations:
        line = d.where.line if d.where else None
        request = excerpt(d.request)
        if d.request not in accepts:
            raise ContractError(f"duration of request {request}: no transition of the chart waits for request "
                                f"{request}", path, line)
        if d.request in seen:
            raise ContractError(f"request {request} has more than one duration", path, line)
        seen.add(d.request)
        if d.seconds is None and (d.motion_of is None or d.top_speed is None):
            raise ContractError(f"duration of request {request}: expected pnp:seconds, or pnp:motionOf with "
                                "pnp:topSpeed", path, line)
        for quantity in (d.motion_of, d.speed_share):
            if quantity is not None and quantity not in accepts[d.request]:
                raise ContractError(f"duration of request {request}: the request does not take "
                                    f"{excerpt(local_name(quantity))} (its pnp:accepts)", path, line)


def _argument(loaded: Loaded, a: rdflib.term.Node) -> Argument:
    """One ``pnp:RequestArgument`` of a device (the shapes check its terms; the limits must be finite)."""
    required = optional_value(loaded, a, PNP.required)
    datatype = optional_value(loaded, a, PNP.datatype)
    return Argument(
        request=str(one_value(loaded, a, PNP.request, "request")),
        quantity=str(one_value(loaded, a, PNP.quantity, "quantity")),
        required=not (isinstance(required, rdflib.Literal) and required.toPython() is False),
        datatype=str(datatype) if datatype is not None else "",
        unit=str(optional_value(loaded, a, PNP.unit) or ""),
        minimum=finite_number(loaded, a, optional_value(loaded, a, PNP.minValue), "minimum"),
        maximum=finite_number(loaded, a, optional_value(loaded, a, PNP.maxValue), "maximum"),
        reach=finite_number(loaded, a, optional_value(loaded, a, PNP.maxReach), "maximum reach"),
        default=plain_default(optional_value(loaded, a, PNP.defaultValue)),
        where=loaded.where(str(a)),
    )


def load_device(path: str | Path, taxonomy: Taxonomy) -> DeviceDescription:
    """Read a device description (Turtle + its Device State Chart)."""
    return device_from(read_description(path), taxonomy)


def load_devices(folder: str | Path, taxonomy: Taxonomy) -> list[DeviceDescription]:
    """Every device description in a folder (a catalogue), sorted by id."""
    return sorted((load_device(f, taxonomy) for f in sorted(Path(folder).glob("*.ttl"))), key=lambda d: d.id)


def load_processes(folder: str | Path) -> list[ProcessDescription]:
    """Every process description in a folder, sorted by command name."""
    return sorted((load_process(f) for f in sorted(Path(folder).glob("*.ttl"))), key=lambda p: p.id)


POSE_DATATYPE = str(PNP.Pose)
NUMERIC = {str(XSD.decimal), str(XSD.integer), str(XSD.double), str(XSD.float)}
