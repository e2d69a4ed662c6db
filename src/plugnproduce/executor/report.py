"""How a run ended, and what stopped it: the report of :class:`plugnproduce.executor.run.TaskRun`."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Fault:
    """What stopped a run.

    ``kind``: ``timeout``, ``refused``, ``lost``, ``anomaly``, ``unexpected``, ``contract`` (an argument
    beyond the device's contract: the request was not sent), ``outcome`` (an outcome the process does not
    declare), ``chart`` (the task chart broke down), ``journal`` (the journal cannot be written) or ``stopped``.
    """

    kind: str
    message: str
    step: int | None = None
    command: str | None = None
    device: str | None = None
    state: str | None = None
    """The device's chart state as the controller last saw it (for a request: when it was sent)."""
    request: str | None = None
    """The device request the fault concerns, if any."""
    argument: str | None = None
    """The request's argument the fault concerns (a breach of the device's contract), if any."""

    def __str__(self) -> str:
        where = f"step {self.step} ({self.command})" if self.step is not None else "before the first step"
        device = f", device {self.device} in state {self.state}" if self.device else ""
        request = f", request {self.request}" if self.request else ""
        return f"{self.kind} at {where}{device}{request}: {self.message}"

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {"fault": self.kind, "message": self.message, "step": self.step, "command": self.command,
                "device": self.device, "state": self.state, "request": self.request, "argument": self.argument}


@dataclass
class RunReport:
    """How a run ended: ``succeeded``, ``failed`` or ``stopped``, and where each device was left."""

    outcome: str
    journal: Path
    fault: Fault | None = None
    device_states: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {"outcome": self.outcome, "journal": str(self.journal),
                "fault": self.fault.to_json() if self.fault else None, "device_states": dict(self.device_states)}
