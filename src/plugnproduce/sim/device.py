"""A simulated device: its own Device State Chart is its program.

A request the chart waits for moves it; an event the chart sends goes out over the
device's protocol. The device is driven over XIRP (an :class:`XirpServer`), UPnP
(an :class:`UpnpDeviceServer` whose actions and evented variables come from the
chart) or OPC UA (an :class:`OpcUaDeviceServer` whose methods and event types come
from the chart) and, whatever its protocol, announces itself by SSDP and serves its own
Turtle and chart, the Turtle naming the endpoint it really listens on. A request the
chart does not wait for in its current state is refused (XIRP ``not-accepted``, UPnP
701, OPC UA ``BadInvalidState``) and does not move the chart.
"""

from __future__ import annotations

import asyncio
import dataclasses
import logging
import math
from collections.abc import Coroutine, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import rdflib

from plugnproduce.description.model import Command, DeviceDescription
from plugnproduce.description.quantities.reports import reported_values
from plugnproduce.ontology.vocabulary import PNP, local_name
from plugnproduce.protocols import upnp, xirp
from plugnproduce.protocols.files import DeviceFiles
from plugnproduce.safeio import parse_turtle
from plugnproduce.sim.bin import SimulatedBin
from plugnproduce.sim.payloads import event_payloads
from plugnproduce.statechart.runtime.events import Event, EventData
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.statechart.runtime.loop import ChartLoop
from plugnproduce.timing.requests import DeviceTimer

if TYPE_CHECKING:
    from plugnproduce.protocols.opcua import OpcUaDeviceServer


def served_description(device: DeviceDescription, endpoint: str) -> tuple[str, str]:
    """The device's Turtle with its real endpoint, and its chart, as text.

    The Turtle is edited as RDF: the device's ``pnp:endpoint`` becomes ``endpoint`` and its ``pnp:stateChart``
    the chart's name, since the chart is served beside the Turtle whatever folder it sits in. Other IRIs the
    file gave relative to its folder stay relative, so they name the served files, not the simulator's.
    """
    path = Path(device.where.file)
    graph, _ = parse_turtle(path)
    subject = rdflib.URIRef(device.iri)
    if graph.value(subject, PNP.endpoint) is None:
        raise ValueError(f"{device.where.file}: {device.id} has no pnp:endpoint to fill in")
    served = _relative_to(graph, path.parent.resolve().as_uri() + "/")
    served.set((subject, PNP.endpoint, rdflib.Literal(endpoint)))
    served.set((subject, PNP.stateChart, rdflib.URIRef(Path(device.chart_file).name)))
    return served.serialize(format="turtle"), Path(device.chart_file).read_text(encoding="utf-8")


def _relative_to(graph: rdflib.Graph, folder: str) -> rdflib.Graph:
    """A copy of ``graph`` whose IRIs inside ``folder`` are written relative to it."""
    def relative(node: Any) -> Any:
        return rdflib.URIRef(node[len(folder):]) if isinstance(node, rdflib.URIRef) and node.startswith(folder) \
            else node

    out = rdflib.Graph()
    for prefix, namespace in graph.namespaces():
        out.bind(prefix, namespace, override=True, replace=True)
    for s, p, o in graph:
        out.add((relative(s), relative(p), relative(o)))
    return out


def requests_and_events(device: DeviceDescription) -> tuple[dict[str, list[str]], list[str]]:
    """The requests the chart waits for (with the quantities they carry) and the events it sends."""
    requests: dict[str, list[str]] = {}
    events: list[str] = []
    for t in (*device.transitions, *device.stops):
        if t.request is not None:
            names = requests.setdefault(t.request.name, [])
            names.extend(local_name(q) for q in t.accepts if local_name(q) not in names)
        events.extend(c.name for c in t.sends if c.kind == "event" and c.name not in events)
    return requests, events

_LOGGER = logging.getLogger(__name__)


class SimulatedDevice:
    """One device running its chart behind its protocol; ``async with`` starts and stops it."""

    def __init__(self, device: DeviceDescription, *, network: upnp.SsdpNetwork = upnp.LOOPBACK,
                 faults: xirp.Faults | None = None, bin: SimulatedBin | None = None,  # noqa: A002
                 lds: str | None = None, speed: float = 1.0) -> None:
        """``bin``: the simulated bin the device works on, if any; ``lds``: the Local Discovery Server an OPC UA
        device registers with, if any; ``speed``: how much faster than real time the device works (its chart's
        delays and declared durations divided by it). A device in a state it reported
        (:meth:`DeviceDescription.reported`) starts its chart there."""
        if not (math.isfinite(speed) and speed > 0):
            raise ValueError(f"speed factor {speed!r}: expected a positive number")
        self.description = device
        self.lds = lds
        self.network = network
        self.faults = faults if faults is not None else xirp.Faults()
        self.bin = bin
        chart = device.chart
        if device.reported_state and [device.initial] != chart.initial:  # it starts where it was left (a resume)
            chart = dataclasses.replace(chart, initial=[device.initial])
        self.interpreter = Interpreter(chart, io_processors={device.protocol: self},
                                       base_dir=Path(device.chart_file).parent)
        self.speed = speed
        self.timer = DeviceTimer(device)
        self.interpreter.delay_policy = self._delay
        self._loop = ChartLoop(self.interpreter)
        self._task: asyncio.Task[None] | None = None
        self._xirp: xirp.XirpServer | None = None
        self._upnp: upnp.UpnpDeviceServer | None = None
        self._opcua: OpcUaDeviceServer | None = None
        self._answers: dict[str, asyncio.Future[dict[str, Any]]] = {}
        """Per event a request is answered with at once (an OPC UA method's output arguments), its caller."""
        self._pending: set[asyncio.Task[Any]] = set()
        self._reports = reported_values(device)

    @property
    def id(self) -> str:
        """The device id."""
        return self.description.id

    @property
    def state(self) -> str:
        """The chart state the device is in."""
        return self.interpreter.configuration[-1] if self.interpreter.configuration else self.description.initial

    def reported(self) -> dict[str, Any]:
        """The values its chart says it reports with its state, as they are now, by quantity (teach-in)."""
        dm = self.interpreter.dm
        return {q: dm[r.variable] for q, r in self._reports.items() if r.variable in dm}

    @property
    def endpoint(self) -> str:
        """Where a controller reaches the device: ``xirp://host:port`` or the UPnP description URL."""
        if self._xirp is not None:
            return self._xirp.endpoint
        if self._opcua is not None and self._opcua.endpoint is not None:
            return self._opcua.endpoint
        if self._upnp is not None and self._upnp.location is not None:
            return self._upnp.location
        raise RuntimeError(f"device {self.id} is not started")

    async def __aenter__(self) -> SimulatedDevice:
        await self.start()
        return self

    async def __aexit__(self, *exc_info: object) -> None:
        await self.stop()

    async def start(self) -> None:
        """Start the chart, listen on the protocol, then announce the device."""
        d = self.description
        self._task = asyncio.create_task(self._loop.run(), name=f"device {d.id}")
        self._task.add_done_callback(self._chart_ended)
        device_class = local_name(d.classes[0])
        requests, events = requests_and_events(d)
        if d.protocol == "xirp":
            self._xirp = xirp.XirpServer(d.id, device_class, self._on_xirp_request, label=d.label,
                                         files=self._files(d.endpoint), faults=self.faults,
                                         host=self.network.interface)
            await self._xirp.start()
            spec = upnp.service_spec_from_chart_events({}, [])
            files = self._xirp.files = self._files(self._xirp.endpoint)
        elif d.protocol == "opcua":
            from plugnproduce.protocols.opcua import OpcUaDeviceServer  # asyncua loads only for an OPC UA device
            from plugnproduce.protocols.opcua.security import device_security
            from plugnproduce.sim.opcua import node_spec

            security = await device_security(d.id)  # PNP_OPCUA_PKI: the folder's missing certificates are made
            self._opcua = OpcUaDeviceServer(node_spec(d), self._on_opcua_call, lambda: self.state,
                                            host=self.network.interface, files=self._files, security=security,
                                            reported=lambda quantity: self.reported().get(quantity))
            await self._opcua.start()
            if self.lds is not None:
                await self._opcua.register(self.lds)
            assert self._opcua.endpoint is not None
            spec = upnp.service_spec_from_chart_events({}, [])
            files = self._files(self._opcua.endpoint)
        else:
            spec = upnp.with_state_query(upnp.service_spec_from_chart_events(requests, events,
                                                                              payloads=event_payloads(d)),
                                         reports=sorted(self._reports))
            files = self._files(d.endpoint)
        self._upnp = upnp.UpnpDeviceServer(d.id, d.label, upnp.device_type_for(device_class), spec,
                                           self._on_upnp_action, files=files, network=self.network)
        await self._upnp.start()

    def _chart_ended(self, task: asyncio.Task[None]) -> None:
        """A chart that broke down (e.g. never settles) is said so; the device then refuses every request."""
        if not task.cancelled() and task.exception() is not None:
            _LOGGER.error("simulated device %s: its chart stopped: %s", self.description.id, task.exception())

    async def stop(self) -> None:
        """Say goodbye (SSDP byebye, XIRP bye) and stop the chart."""
        if self._upnp is not None:
            await self._upnp.stop()
        if self._xirp is not None:
            await self._xirp.stop()
        if self._opcua is not None:
            await self._opcua.stop()
        if self._task is not None:
            self._task.cancel()
            await asyncio.gather(self._task, *self._pending, return_exceptions=True)
        self._upnp = self._xirp = self._task = self._opcua = None

    async def drop_connections(self) -> int:
        """Abort every XIRP connection (a cable pulled); the device stays announced."""
        return await self._xirp.disconnect_all() if self._xirp is not None else 0

    def _files(self, endpoint: str) -> DeviceFiles:
        d = self.description
        turtle, chart = served_description(d, endpoint)
        return DeviceFiles(Path(d.where.file).name, turtle, Path(d.chart_file).name, chart)

    # --- requests in ----------------------------------------------------------------

    def _accept(self, request: str, params: Mapping[str, Any]) -> None:
        """Feed a request to the chart, or refuse it if the current state does not wait for it."""
        event = Command(self.description.protocol, "request", request).event
        d = self.description
        waits = {t.event for t in (*d.transitions, *d.stops) if t.source == self.state}
        if event not in waits:
            raise LookupError(f"device {self.id} is {self.state}; it does not accept {request} now")
        if self.bin is not None:
            self.bin.on_request(self.description, params, self.interpreter.dm)
        self.timer.request(request, params)
        self._loop.queue(event, EventData(params))  # its values read as _event.data.NAME too, as in any interpreter

    def _delay(self, nominal: float) -> float:
        """A delayed send of the chart: the declared duration of the request just taken (once) or the chart's
        delay, scaled by the speed factor."""
        return self.timer.delay(nominal) / self.speed

    def _on_xirp_request(self, request: xirp.Request) -> xirp.Results:
        if request.name == xirp.STATE:  # with the values its chart says it reports (teach-in reads them)
            return {xirp.STATE_RESULT: self.state, **self.reported()}
        try:
            self._accept(request.name, request.params)
        except LookupError as exc:
            raise xirp.RequestFailed(str(exc), xirp.NOT_ACCEPTED) from None
        return None

    async def _on_opcua_call(self, request: str, values: Mapping[str, Any]) -> Mapping[str, Any] | None:
        """A method call: the request goes to the chart; the answer's values, if it has one, come back."""
        from plugnproduce.protocols.opcua import RequestRefused

        answer = self.description.answer_to(request)
        waiter = asyncio.get_running_loop().create_future() if answer is not None else None
        if answer is not None and waiter is not None:
            self._answers[answer] = waiter
        try:
            self._accept(request, values)
        except LookupError as exc:
            self._answers.pop(answer or "", None)
            raise RequestRefused(str(exc)) from None
        if waiter is None:
            return None
        try:
            return await asyncio.wait_for(waiter, self.description.command_timeout)
        finally:
            self._answers.pop(answer or "", None)

    async def _on_upnp_action(self, action: str, arguments: Mapping[str, Any]) -> Mapping[str, Any]:
        if action == upnp.STATE_ACTION:
            reported = {q: upnp.report_text(v) for q, v in self.reported().items()}
            return {upnp.STATE_ARGUMENT: self.state, **reported}
        values = self._upnp_values(action, arguments)
        try:
            self._accept(action, values)
        except LookupError as exc:
            raise upnp.ActionFailed(str(exc), upnp.NOT_ACCEPTED_NOW) from None
        return {"Result": "accepted"}

    def _upnp_values(self, action: str, arguments: Mapping[str, Any]) -> dict[str, Any]:
        """The action's arguments read as strictly as their datatypes say (a pose joined with commas is refused)."""
        d = self.description
        quantities = {local_name(q): q for t in (*d.transitions, *d.stops)
                      if t.request is not None and t.request.name == action for q in t.accepts}
        values: dict[str, Any] = {}
        for name, text in arguments.items():
            datatype = local_name(d.argument(action, quantities[name]).datatype) if name in quantities else ""
            try:
                values[name] = upnp.parse_lexical(text, datatype) if isinstance(text, str) else text
            except ValueError as exc:
                raise upnp.ActionFailed(f"device {self.id}: {action} argument {name}: {exc}",
                                        upnp.ARGUMENT_VALUE_INVALID) from None
        return values

    # --- events out (the chart's I/O processor) ------------------------------------------

    def send(self, event: Event, target: str | None, type: str) -> None:  # noqa: A002 - the SCXML name
        """The chart sent ``PROTOCOL.event.NAME``: send it to the controllers."""
        command = Command.parse(event.name)
        if command is None or command.kind != "event":
            raise ValueError(f"device {self.id} cannot send {event.name!r}; expected {type}.event.NAME")
        if self._xirp is not None:
            self._xirp.emit(command.name, dict(event.data or {}))
        elif self._opcua is not None:
            waiter = self._answers.pop(command.name, None)
            if waiter is not None and not waiter.done():
                waiter.set_result(dict(event.data or {}))  # the method's output arguments
                return
            self._schedule(self._opcua.emit(command.name, dict(event.data or {})))
        elif self._upnp is not None:
            self._schedule(self._upnp.emit(command.name, dict(event.data or {})))

    def _schedule(self, sending: Coroutine[Any, Any, object]) -> None:
        task = asyncio.get_running_loop().create_task(sending)
        self._pending.add(task)
        task.add_done_callback(self._pending.discard)
