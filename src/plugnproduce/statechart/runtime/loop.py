"""An interpreter run in asyncio: external events in, delayed sends on time, each macrostep reported.

>>> loop = ChartLoop(Interpreter(chart))       # doctest: +SKIP
>>> task = asyncio.create_task(loop.run())     # doctest: +SKIP
>>> loop.queue("xirp.request.Open")            # doctest: +SKIP
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable
from typing import Any

from plugnproduce.statechart.runtime.events import MacroStep
from plugnproduce.statechart.runtime.interpreter import Interpreter

StepCallback = Callable[[MacroStep], None]
"""Called with every macrostep as soon as it is done."""


class ChartLoop:
    """Drives one :class:`Interpreter` with the event loop's clock until it stops or is cancelled."""

    def __init__(self, interpreter: Interpreter, on_step: StepCallback | None = None) -> None:
        self.interpreter = interpreter
        self._on_step = on_step
        self._wake = asyncio.Event()

    def queue(self, name: str, data: Any = None) -> None:
        """An external event for the chart; it is processed at the next turn of the loop."""
        self.interpreter.queue(name, data)
        self._wake.set()

    async def run(self) -> None:
        """Start the chart and process events and due sends until it reaches a top-level final state."""
        chart = self.interpreter
        try:
            if not chart.started:
                self._report(chart.start())
            while chart.running:
                self._wake.clear()
                for step in chart.execute():
                    self._report(step)
                if not chart.running:
                    break
                due = chart.next_due()
                timeout = None if due is None else max(0.0, due - chart.clock.time())
                with contextlib.suppress(TimeoutError):
                    await asyncio.wait_for(self._wake.wait(), timeout)
        finally:
            chart.release()  # a session cancelled while it runs lets go of what it holds, as one that ended

    def _report(self, step: MacroStep) -> None:
        if self._on_step is not None:
            self._on_step(step)
