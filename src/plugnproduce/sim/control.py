"""The simulated cell's control channel: ``pnp sim plug/unplug`` talk to ``pnp sim up``.

One JSON object per line over TCP on loopback: ``{"op": "plug", "device": "gripper"}``
is answered by ``{"ok": true, "devices": [...]}`` or ``{"ok": false, "error": "..."}``.
``pnp sim up`` writes where it listens to a small state file, which the other commands
read unless given ``--control HOST:PORT``.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

from plugnproduce import folders
from plugnproduce.errors import ProtocolConnectionError, ProtocolError

Handler = Callable[[str, str], Awaitable[list[str]]]
"""``await handler(op, device)`` → the devices running afterwards; raises ``ProtocolError`` to refuse."""

MAX_LINE = 4096


def default_state_file() -> Path:
    """Where a running simulated cell says where its control channel listens."""
    return folders.cache_folder() / "sim-control.json"


class ControlServer:
    """Serves control requests on a free loopback port."""

    def __init__(self, handler: Handler, host: str = "127.0.0.1", port: int = 0) -> None:
        self._handler = handler
        self._host, self._port = host, port
        self._server: asyncio.Server | None = None

    @property
    def address(self) -> tuple[str, int]:
        """The host and port it listens on."""
        if self._server is None:
            raise RuntimeError("control server not started")
        host, port = self._server.sockets[0].getsockname()[:2]
        return str(host), int(port)

    async def start(self) -> None:
        """Listen."""
        self._server = await asyncio.start_server(self._serve, self._host, self._port, limit=MAX_LINE)

    async def stop(self) -> None:
        """Stop listening."""
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()
            self._server = None

    def write_state(self, path: Path) -> None:
        """Record the address for the other ``pnp sim`` commands."""
        path.parent.mkdir(parents=True, exist_ok=True)
        host, port = self.address
        path.write_text(json.dumps({"host": host, "port": port, "pid": os.getpid()}))

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            line = await reader.readline()
            answer = await self._answer(line)
            writer.write((json.dumps(answer) + "\n").encode())
            await writer.drain()
        except (ConnectionError, asyncio.LimitOverrunError, ValueError):
            pass  # a broken client costs only its own connection
        finally:
            writer.close()
            with contextlib.suppress(ConnectionError):
                await writer.wait_closed()

    async def _answer(self, line: bytes) -> dict[str, Any]:
        try:
            request = json.loads(line)
            op, device = str(request["op"]), str(request.get("device", ""))
        except (ValueError, KeyError, TypeError):
            return {"ok": False, "error": 'expected one JSON line like {"op": "plug", "device": "gripper"}'}
        try:
            return {"ok": True, "devices": await self._handler(op, device)}
        except ProtocolError as exc:
            return {"ok": False, "error": str(exc)}


def read_state(path: Path | None = None) -> tuple[str, int]:
    """The control address a running ``pnp sim up`` recorded."""
    p = path or default_state_file()
    try:
        data = json.loads(p.read_text())
        host, port, pid = str(data["host"]), int(data["port"]), data.get("pid")
    except (OSError, ValueError, KeyError, AttributeError) as exc:
        raise ProtocolConnectionError("no simulated cell is running (start one with 'pnp sim up CELL')") from exc
    if isinstance(pid, int) and not _alive(pid):  # its port may be anyone's now: never send it a request
        raise ProtocolConnectionError(stopped(host, port))
    return host, port


def stopped(host: str, port: int) -> str:
    """The refusal of the control address of a simulated cell that has stopped."""
    return (f"the simulated cell started last (control {host}:{port}) has stopped; start one with "
            "'pnp sim up CELL', or name a running one with --control HOST:PORT")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # a process we may not signal is alive; a number no pid can be is not ours to judge
    return True


async def request(address: tuple[str, int], op: str, device: str = "", timeout: float = 10.0) -> list[str]:
    """Ask the simulated cell to do ``op`` with ``device``; returns the devices running afterwards."""
    try:
        async with asyncio.timeout(timeout):
            reader, writer = await asyncio.open_connection(*address)
            writer.write((json.dumps({"op": op, "device": device}) + "\n").encode())
            await writer.drain()
            line = await reader.readline()
            writer.close()
            await writer.wait_closed()
    except (OSError, TimeoutError) as exc:
        raise ProtocolConnectionError(f"simulated cell at {address[0]}:{address[1]} does not answer") from exc
    answer = json.loads(line or b"{}")
    if not answer.get("ok"):
        raise ProtocolError(str(answer.get("error", "the simulated cell refused")))
    return [str(d) for d in answer["devices"]]
