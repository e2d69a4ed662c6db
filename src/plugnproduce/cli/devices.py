"""``pnp discover`` and ``pnp sim``: the live cell and the simulated one."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from plugnproduce.cli.application import (
    INTERFACE_OPTION,
    JSON_OPTION,
    app,
    boundary,
    emit_json,
    fail,
    interface_address,
    knowledge,
)
from plugnproduce.cli.console.helptext import PlainTyper
from plugnproduce.errors import ProtocolConnectionError, ProtocolError
from plugnproduce.lazy import lazy_module

if TYPE_CHECKING:
    import asyncio  # the network stack is imported by the commands that use it

    from plugnproduce import service
    from plugnproduce.controller import CellChange, LiveCell, devices
    from plugnproduce.service import Cell
else:
    asyncio = lazy_module("asyncio")  # the event loop is started by the commands that use it
    devices = lazy_module("plugnproduce.controller.devices")
    service = lazy_module("plugnproduce.service")

sim_app = PlainTyper(no_args_is_help=True, rich_markup_mode=None,
                      help="Run simulated devices: the paper's bin-picking cell and more.")
app.add_typer(sim_app, name="sim")


def _device_json(cell: Cell) -> list[service.DeviceView]:
    taxonomy = knowledge().taxonomy
    return [service.device_view(d, taxonomy) for d in cell.devices]


def _offered(cell: Cell) -> list[str]:
    return service.capabilities(cell, knowledge()).commands() if cell.devices else []


def _change_json(change: CellChange) -> dict[str, object]:
    return {"change": change.kind, "device": change.device, "reason": change.reason or None,
            "url": change.location or None,
            "devices": [d.id for d in change.cell.devices], "offered": _offered(change.cell)}


def _refused_json(live: LiveCell) -> list[dict[str, str]]:
    return [{"udn": r.udn, "url": r.location, "reason": r.reason}
            for r in sorted(live.refused.values(), key=lambda r: r.udn)]


@app.command()
@boundary
def discover(
    json_out: bool = JSON_OPTION,
    watch: bool = typer.Option(False, "--watch", help="Keep watching: stream plug and unplug events."),
    timeout: float = typer.Option(10.0, metavar="SECONDS", min=0.1, max=3600,
                                  help="Most seconds to search; the search ends earlier once the answers settle."),
    settle: float = typer.Option(2.0, "--settle", metavar="SECONDS", min=0.1, max=600,
                                 help="The answers have settled when no new device answered for this long."),
    expect: int | None = typer.Option(None, "--expect", metavar="N", min=1, max=10_000,
                                      help="Wait (up to --timeout) for N devices; exit 1 if fewer are found."),
    cell: Path | None = typer.Option(None, "--cell", metavar="CELL",
                                     help="Wait (up to --timeout) for this cell's devices; exit 1 naming those "
                                          "missing."),
    interface: str | None = INTERFACE_OPTION,
    lds: str | None = typer.Option(None, "--lds", metavar="opc.tcp://HOST:PORT",
                                   help="Also the OPC UA devices registered with this Local Discovery Server "
                                        "(FindServers); default PNP_LDS."),
    serve_lds: int | None = typer.Option(None, "--serve-lds", metavar="PORT", min=0, max=65535,
                                         help="Run a Local Discovery Server on the controller's address at PORT "
                                              "(0: a free one; 4840 is the standard) for the OPC UA devices to "
                                              "register with; with --watch they plug and unplug live."),
) -> None:
    """List the devices found on the network (SSDP on loopback or --interface, and the OPC UA devices registered
    with --lds or --serve-lds), with class and skills, and those refused.

    The search ends when no new device answered for --settle seconds, at the latest after --timeout;
    with --expect or --cell it waits for those devices instead. Exit 0 found, 1 some expected device
    missing, 2 bad input.
    """
    address = interface_address(interface)
    if lds is not None and serve_lds is not None:
        fail("--lds and --serve-lds: give one (ask that LDS, or run one here)")
    wanted = [d.id for d in service.cell(cell, knowledge(cell)).devices] if cell is not None else []
    search = Search(timeout, settle, expect, wanted, lds, serve_lds)
    try:
        missing = asyncio.run(_discover(json_out, watch, search, address))
    except KeyboardInterrupt:
        return
    if missing:
        raise typer.Exit(1)


@dataclass(frozen=True)
class Search:
    """How long ``pnp discover`` searches and what for."""

    timeout: float
    settle: float
    expect: int | None
    wanted: list[str]
    lds: str | None = None
    """The Local Discovery Server to ask, if any."""
    serve_lds: int | None = None
    """The port of the Local Discovery Server to run, if any."""

    @property
    def waits(self) -> bool:
        """Whether the search waits for devices rather than for the answers to settle."""
        return self.expect is not None or bool(self.wanted)

    def missing(self, cell: Cell) -> list[str]:
        """What of the expected is not in ``cell``."""
        present = [d.id for d in cell.devices]
        named = [d for d in self.wanted if d not in present]
        if self.expect is not None and len(present) < self.expect:
            return [*named, f"{self.expect - len(present)} of {self.expect} device(s)"] if not named else named
        return named

    def summary(self, seconds: float, missing: list[str]) -> str:
        """One line: how long it searched, why it stopped, and what may be missing."""
        if missing:
            return f"missing after {seconds:.1f} s of search (--timeout {self.timeout:g}): {', '.join(missing)}"
        if self.waits:
            return f"searched {seconds:.1f} s: every expected device answered"
        why = (f"no new device for {self.settle:g} s" if seconds < self.timeout else f"--timeout {self.timeout:g} s")
        return (f"searched {seconds:.1f} s (until {why}); devices that answer later may be missing "
                f"(--expect N or --cell CELL waits for them)")


async def _discover(json_out: bool, watch: bool, search: Search, address: str) -> list[str]:
    began = time.monotonic()
    served: list[str] = []

    def serving(endpoint: str) -> None:
        served.append(endpoint)
        if not json_out:
            typer.echo(f"{'lds':16} opcua {endpoint}")

    async with devices.discovery(knowledge(), search_timeout=search.timeout, expected=search.wanted,
                                 expected_count=search.expect, quiet=None if search.waits else search.settle,
                                 interface=address, lds=search.lds, serve_lds=search.serve_lds,
                                 echo=serving) as live:
        cell, seconds = live.cell, time.monotonic() - began
        missing = search.missing(cell)
        _show_found(live, cell, json_out, watch, {"searched_seconds": round(seconds, 1), "missing": missing,
                                                  "summary": search.summary(seconds, missing),
                                                  **({"lds": served[0]} if served else {})})
        if missing and not json_out:
            typer.echo(f"error: {search.summary(seconds, missing)}", err=True)
        if watch:
            await _watch(live, cell, json_out)
    return missing


def _show_found(live: LiveCell, cell: Cell, json_out: bool, watch: bool, search: dict[str, object]) -> None:
    found = {"devices": _device_json(cell), "refused": _refused_json(live), "offered": _offered(cell), **search}
    if json_out and watch:  # one JSON object per line from the first on
        typer.echo(json.dumps(found))
    elif json_out:
        emit_json(found)
    else:
        for d in _device_json(cell):
            typer.echo(f"{d['id']:16} {', '.join(d['classes']):22} {d['protocol']:5} {', '.join(d['skills'])}")
        for r in _refused_json(live):
            typer.echo(f"refused {_refused_what(r['udn'], r['url'])}{r['reason']}")
        typer.echo(f"offered: {', '.join(_offered(cell)) or 'nothing'}")
        if not search["missing"]:
            typer.echo(str(search["summary"]))


def _refused_what(udn: str, url: str) -> str:
    """What was refused, before the reason: ``UDN at URL: ``; nothing for a Local Discovery Server (named by its
    URL: the reason names it)."""
    return "" if udn == url else f"{udn} at {url}: "


async def _watch(live: LiveCell, cell: Cell, json_out: bool) -> None:
    shown = {d.id for d in cell.devices}
    refusals_shown = {(r.udn, r.location, r.reason) for r in live.refused.values()}
    while True:
        change = await live.next_change()
        if change.kind != "refused" and (change.device in shown) == (change.kind == "plug"):
            continue  # already shown (the devices found at start are also queued as plugs)
        if change.kind == "refused" and (change.device, change.location, change.reason) in refusals_shown:
            refusals_shown.discard((change.device, change.location, change.reason))
            continue
        shown = {d.id for d in change.cell.devices}
        line = _change_json(change)
        if json_out:
            typer.echo(json.dumps(line))
        else:
            if change.kind == "refused":
                typer.echo(f"refused {_refused_what(change.device, change.location)}{change.reason}")
            else:
                typer.echo(f"{change.kind} {change.device}" + (f" at {change.location}" if change.location else ""))
            typer.echo(f"offered: {', '.join(line['offered']) or 'nothing'}")  # type: ignore[arg-type]


def _address(control_address: str | None) -> tuple[str, int]:
    if control_address:
        host, _, port = control_address.rpartition(":")
        if not host or not port.isdigit():
            fail(f"--control: expected HOST:PORT; found {control_address!r}")
        return host, int(port)
    return devices.control_address()


CONTROL = typer.Option(None, "--control", metavar="HOST:PORT",
                       help="HOST:PORT of the running simulated cell (default: the last started).")


@sim_app.command("plug")
@boundary
def sim_plug(device: str = typer.Argument(..., metavar="DEVICE",
                                          help="A catalogue device id or a device description file."),
             control_address: str | None = CONTROL) -> None:
    """Plug a simulated device into the running cell.

    Exit 0 plugged, 2 bad input (an unknown device, no running cell at the control address).
    """
    path = Path(device)
    if device.endswith(".ttl") or path.is_file():
        if not path.is_file():
            fail(f"{device}: device description file not found")
        device = str(path.resolve())
    _control("plug", device, control_address)


@sim_app.command("unplug")
@boundary
def sim_unplug(device: str = typer.Argument(..., metavar="DEVICE", help="The id of a running device."),
               control_address: str | None = CONTROL) -> None:
    """Unplug a simulated device from the running cell.

    Exit 0 unplugged, 2 bad input (no such device, no running cell at the control address).
    """
    _control("unplug", device, control_address)


def _control(op: str, device: str, control_address: str | None) -> None:
    address = _address(control_address)
    try:
        running = asyncio.run(devices.control_request(address, op, device))
    except ProtocolConnectionError as exc:  # the address the cell started last recorded: it may have stopped
        hint = "" if control_address else "; start a cell with 'pnp sim up CELL', or name one with --control HOST:PORT"
        fail(f"error: {exc}{hint}")
    except ProtocolError as exc:
        fail(f"error: {exc}")
    typer.echo(f"{op}ged {device}; running: {', '.join(running)}")


@sim_app.command("up")
@boundary
def sim_up(
    cell: Path = typer.Argument(..., metavar="CELL", help="A cell file, e.g. descriptions/cells/bin-picking.yaml."),
    faults: str = typer.Option("", "--faults", metavar="SPEC",
                               help="Faults to inject: DEVICE:KIND[:NAME[:SECONDS]],... "
                                    "e.g. 'gripper:drop-response:Close'."),
    state_file: Path | None = typer.Option(None, metavar="FILE", help="Where to record the control address."),
    bin_parts: int | None = typer.Option(None, "--bin-parts", metavar="N", min=0, max=10_000,
                                         help="A simulated bin of N parts at random poses for the devices to work on."),
    bin_seed: int = typer.Option(0, "--bin-seed", metavar="S", help="With --bin-parts: the seed that places them."),
    speed: float = typer.Option(1.0, "--speed", metavar="F", min=0.01, max=1000.0,
                                help="The devices work F times faster than real time (their durations divided by F; "
                                     "default 1)."),
    interface: str | None = INTERFACE_OPTION,
    lds: str | None = typer.Option(None, "--lds", metavar="opc.tcp://HOST:PORT",
                                   help="The OPC UA devices register with this Local Discovery Server."),
    serve_lds: int | None = typer.Option(None, "--serve-lds", metavar="PORT", min=0, max=65535,
                                         help="Start a Local Discovery Server on the cell's address at PORT "
                                              "(0: a free one) and register the OPC UA devices with it."),
) -> None:
    """Start the cell's simulated devices; Ctrl-C stops them cleanly.

    Plug in more with 'pnp sim plug DEVICE' (a device of the libraries, or a device description file).
    The devices announce themselves and listen on --interface (default PNP_INTERFACE, else loopback);
    PNP_SSDP_PORT chooses a private SSDP port.

    Exit 0 stopped by Ctrl-C or SIGTERM, 2 bad input (a cell that cannot be read or started).
    """
    address = interface_address(interface)  # an unknown interface is said before anything is loaded
    the_cell = service.cell(cell, knowledge())
    k = knowledge(cell)
    if lds is not None and serve_lds is not None:
        fail("--lds and --serve-lds: give one (register with that LDS, or with the one started here)")
    sim = devices.simulated_cell(the_cell, service.catalogue(knowledge=k), k, faults, bin_parts, bin_seed,
                                 interface=address, speed=speed, lds=lds)
    try:
        asyncio.run(devices.run_simulated(sim, state_file, echo=typer.echo, serve_lds=serve_lds))
    except KeyboardInterrupt:
        typer.echo("stopped")
