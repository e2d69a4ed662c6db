"""The project's runtime and python-statemachine, an independent interpreter, agree on the closed-world charts."""

from __future__ import annotations

from pathlib import Path

import pytest
from statechart_support import run_to_end
from statemachine.io.scxml.processor import SCXMLProcessor

from plugnproduce import service
from plugnproduce.codegen.closed_world import closed_world_chart
from plugnproduce.statechart import parse_chart
from plugnproduce.statechart.runtime.clock import ManualClock
from plugnproduce.statechart.runtime.events import EVENT_CONSUMED, TRANSITION_TAKEN, MetaEvent
from plugnproduce.statechart.runtime.interpreter import Interpreter
from plugnproduce.verification import Budget

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


COUNTING = Path(__file__).parents[1] / "data" / "libraries" / "counting-gripper"


def test_a_library_chart_that_assigns_and_tests_its_variables_reaches_done_in_both_interpreters() -> None:
    # The counting gripper's chart (a library outside the package) adds to its count with <assign>, computes
    # one variable from two others, tests them in <if> and in a transition's cond (with In() on its own state)
    # and reports the count in an event: in the closed world every one of those expressions must read the
    # device's renamed variables and states, as verify and the simulated device do.
    cell_file = COUNTING / "cells" / "bin-picking-counting.yaml"
    k = service.knowledge_for_cell(cell_file)
    cell = service.cell(cell_file, k)
    generated = service.generate(COUNTING / "tasks" / "bin-picking-counting.yaml", cell, knowledge=k,
                                 verify=Budget())
    assert generated.verification is not None and generated.verification.proved
    chart = closed_world_chart(generated.task, cell)
    theirs, ours = in_python_statemachine(chart), in_our_runtime(chart)
    assert ours[0] == theirs[0] == {"done"}
    assert ours[1] == theirs[1] and ours[1].count("counting-gripper.xirp.request.Close") == 3
