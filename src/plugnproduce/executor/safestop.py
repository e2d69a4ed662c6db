"""The safe stop after a run that ends by a fault or a stop (the operator's, SIGINT, SIGTERM).

Each connected device is asked its state, sent the safe-stop request its chart takes
there (a transition annotated ``pnp:SafeStop``), and asked its state again; each answer
is journalled as a ``stop`` record. All devices are stopped at once, each answer bounded
in time.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Mapping
from typing import Any, Protocol

from plugnproduce.description.model import Cell, DeviceDescription
from plugnproduce.errors import PlugNProduceError, ProtocolTimeout
from plugnproduce.executor.links import DeviceLink

STOP_TIMEOUT = 5.0
"""The longest wait, in seconds, for each answer of the safe stop (a device's command timeout if shorter)."""


class Recorder(Protocol):
    """Writes one journal record."""

    def __call__(self, kind: str, **data: Any) -> None:
        """Journal a record of ``kind`` with ``data``."""


async def stop_safely(cell: Cell, links: Mapping[str, DeviceLink], device_states: dict[str, str],
                      record: Recorder) -> None:
    """Stop every connected device safely, at once; ``device_states`` gets the state each reports last."""
    await asyncio.gather(*(_stop_device(cell.device(d), link, device_states, record) for d, link in links.items()))


async def _stop_device(device: DeviceDescription, link: DeviceLink, device_states: dict[str, str],
                       record: Recorder) -> None:
    timeout = min(device.command_timeout, STOP_TIMEOUT)
    seen = device_states.get(device.id, device.initial)
    try:
        state = await link.state(timeout)
    except PlugNProduceError as exc:
        record("stop", device=device.id, state=seen, request=None, answer=f"no state reported: {exc}")
        return
    stop = device.stop_from(state)
    if stop is None or stop.request is None:
        record("stop", device=device.id, state=state, request=None, answer=None)
    else:
        request = stop.request.name
        try:
            await link.request(request, {}, timeout)
            answer = "accepted"
        except ProtocolTimeout:
            answer = f"no answer within {timeout:g} s"
        except PlugNProduceError as exc:
            answer = f"refused: {exc}"
        with contextlib.suppress(PlugNProduceError):
            state = await link.state(timeout)
        record("stop", device=device.id, state=state, request=request, answer=answer)
    device_states[device.id] = state
