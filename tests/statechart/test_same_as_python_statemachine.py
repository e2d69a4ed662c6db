"""The project's runtime and python-statemachine, an independent interpreter, agree on the closed-world charts."""

from __future__ import annotations

import pytest
from statechart_support import run_to_end
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import EVENT_CONSUMED, TRANSITION_TAKEN, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter

CELL = service.builtin("cells", "bin-picking.yaml")


def is_command(name: str) -> bool:
    """A device command of the closed-world chart: ``DEVICE.PROTOCOL.request.NAME``."""
    return ".request." in name


def in_python_statemachine(chart: bytes) -> tuple[set[str], list[str]]:
    """Final configuration, and the commands that device models took transitions on, in order."""
    taken: list[str] = []

    class Listener:
        def after_transition(self, event: object, source: object, target: object) -> None:
            taken.append(str(event))

    processor = SCXMLProcessor()
    processor.parse_scxml("closed_world", chart.decode())
    machine = processor.start(listeners=[Listener()])
    return set(machine.configuration_values), [e for e in taken if is_command(e)]


def in_our_runtime(chart: bytes) -> tuple[set[str], list[str]]:
    """The same, from this runtime's meta events."""
    taken: list[str] = []
    current: list[str] = []

    def observe(meta: MetaEvent) -> None:
        if meta.name == EVENT_CONSUMED:
            current[:] = [meta.data["event"].name]
        elif meta.name == TRANSITION_TAKEN and meta.data["transition"].event is not None:
            taken.extend(current)

    clock = ManualClock()
    interpreter = Interpreter(parse_chart(chart, "closed_world"), clock=clock)
    interpreter.attach(observe)
    run_to_end(interpreter, clock)
    return {interpreter.final_state or "(still running)"}, [e for e in taken if is_command(e)]


@pytest.mark.parametrize("task", ["bin-picking", "pick-and-place"])
def test_same_final_configuration_and_order_of_device_commands(task: str) -> None:
    generated = service.generate(service.builtin("tasks", f"{task}.yaml"), CELL).task
    chart = closed_world_chart(generated, service.cell(CELL))
    theirs, ours = in_python_statemachine(chart), in_our_runtime(chart)
    assert ours[0] == theirs[0] == {"done"}
    assert ours[1] == theirs[1]
    assert len(ours[1]) == sum(c.kind == "request" for _, _, c in generated.commands())
