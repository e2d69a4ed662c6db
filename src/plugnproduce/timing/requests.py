"""How long one device takes: the delays of its Device State Chart, or its declared request durations.

The chart's delays are the ``<send delay="...">`` elements that a state's ``onentry`` (or a transition
into it) schedules: a transition triggered by such an event takes that delay. A declared duration
(:mod:`plugnproduce.description.quantities.durations`) replaces the first delay that follows the request. The
simulator and the estimate both time a device with a :class:`DeviceTimer`, so they agree by construction.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from plugnproduce.description.model import ChartTransition, DeviceDescription
from plugnproduce.description.quantities.durations import RequestTimer
from plugnproduce.statechart.model import OnEntry, Parallel, Send, State, Transition, iter_states
from plugnproduce.statechart.runtime.actions import parse_delay
from plugnproduce.statechart.runtime.evaluator import EvaluationError


def chart_delays(device: DeviceDescription) -> dict[tuple[str, str], float]:
    """(state id, event) → seconds: the delayed sends each state schedules on its entry, or that the
    transitions into it do."""
    out: dict[tuple[str, str], float] = {}
    for state in iter_states(device.chart):
        if not isinstance(state, State | Parallel) or state.id is None:
            continue
        for block in state.onentry:
            _add(out, state.id, _sends(block))
        for t in state.transitions:
            for target in t.targets:
                _add(out, target, _sends(t))
    return out


def _sends(block: OnEntry | Transition) -> Iterable[Send]:
    return (a for a in block.actions if isinstance(a, Send))


def _add(out: dict[tuple[str, str], float], state: str, sends: Iterable[Send]) -> None:
    for send in sends:
        if send.event and send.delay:
            try:
                out[(state, send.event)] = parse_delay(send.delay)
            except EvaluationError:
                continue  # a delay the runtime will refuse too; the chart's checks report it


class DeviceTimer:
    """Times one device's transitions, one after the other, as the device takes them."""

    def __init__(self, device: DeviceDescription) -> None:
        self.device = device
        self._delays = chart_delays(device)
        limit = next((a.maximum for d in device.durations if d.speed_share for a in device.arguments
                      if a.request == d.request and a.quantity == d.speed_share and a.maximum), None)
        self._requests = RequestTimer(device.durations, limit or 100.0)
        self._declared: float | None = None

    def state(self) -> tuple[float | None, object]:
        """What its next times depend on: the declared time of the request just taken, the pose it is at."""
        return self._declared, self._requests.pose

    def resume(self, state: tuple[float | None, object]) -> None:
        """Continue from ``state`` (as :meth:`state` gave it), as if it had taken what led there."""
        self._declared, self._requests.pose = state

    def request(self, name: str, values: Mapping[str, object]) -> float | None:
        """The device takes request ``name`` with ``values`` (by quantity local name): its declared time,
        which replaces the next delay (None: the chart's delays count)."""
        self._declared = self._requests.seconds(name, values)
        return self._declared

    def delay(self, nominal: float) -> float:
        """The time a delayed send of ``nominal`` seconds takes: the declared time of the request just
        taken, once, else ``nominal``."""
        declared, self._declared = self._declared, None
        return nominal if declared is None else declared

    def transition(self, edge: ChartTransition, values: Mapping[str, object]) -> float:
        """Seconds the device spends on ``edge`` of its chart (a request is instant; the delay follows)."""
        request = edge.request
        if request is not None:
            self.request(request.name, values)
            return 0.0
        nominal = self._delays.get((edge.source, edge.event or ""))
        return 0.0 if nominal is None else self.delay(nominal)
