"""Large charts are kept out of the cyclic collector's walk while they run, and let go after."""

from __future__ import annotations

import gc
from collections.abc import Iterator

import pytest

from plugnproduce.statechart import SCXML_NS, gcpause, parse_chart
from plugnproduce.statechart.runtime.interpreter import Interpreter

CHART = (f'<scxml xmlns="{SCXML_NS}" version="1.0" datamodel="python" initial="a">'
         '<state id="a"><transition event="go" target="b"/></state><final id="b"/></scxml>').encode()


@pytest.fixture
def nothing_frozen() -> Iterator[None]:
    assert gcpause.holders() == 0
    gc.unfreeze()
    yield
    while gcpause.holders():
        gcpause.release()
    gc.unfreeze()


def test_the_last_release_unfreezes(nothing_frozen: None) -> None:
    gcpause.hold()
    assert gc.get_freeze_count() > 0
    gcpause.hold()
    gcpause.release()
    assert gc.get_freeze_count() > 0, "one session still holds"
    gcpause.release()
    assert gc.get_freeze_count() == 0
    gcpause.release()  # more releases than holds change nothing
    assert gcpause.holders() == 0


def test_a_large_session_holds_while_it_runs(nothing_frozen: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(gcpause, "LARGE_CHART", 1)
    interpreter = Interpreter(parse_chart(CHART, "large"))
    assert gcpause.holders() == 0, "compiling alone does not hold"
    interpreter.start()
    assert gcpause.holders() == 1
    assert gc.get_freeze_count() > 0
    interpreter.queue("go").execute()
    assert interpreter.final_state == "b"
    assert gcpause.holders() == 0
    assert gc.get_freeze_count() == 0


def test_a_small_session_leaves_the_collector_alone(nothing_frozen: None) -> None:
    interpreter = Interpreter(parse_chart(CHART, "small"))
    interpreter.start()
    assert gcpause.holders() == 0
    assert gc.get_freeze_count() == 0


def test_compiling_leaves_the_collector_as_it_found_it() -> None:
    assert gc.isenabled()
    Interpreter(parse_chart(CHART, "on"))
    assert gc.isenabled()
    gc.disable()
    try:
        Interpreter(parse_chart(CHART, "off"))
        assert not gc.isenabled()
    finally:
        gc.enable()


async def test_a_loop_cancelled_mid_session_lets_go(nothing_frozen: None, monkeypatch: pytest.MonkeyPatch) -> None:
    import asyncio

    from plugnproduce.statechart.runtime.loop import ChartLoop

    monkeypatch.setattr(gcpause, "LARGE_CHART", 1)
    interpreter = Interpreter(parse_chart(CHART, "abandoned"))
    task = asyncio.create_task(ChartLoop(interpreter).run())
    async with asyncio.timeout(60):
        while not interpreter.started:
            await asyncio.sleep(0)
    assert gcpause.holders() == 1
    task.cancel()
    with pytest.raises(asyncio.CancelledError):
        await task
    assert interpreter.running
    assert gcpause.holders() == 0
    assert gc.get_freeze_count() == 0
