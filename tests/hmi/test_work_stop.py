"""The HMI's worker processes stop with the application even while they are still starting (their fork server
still importing what every worker needs, which takes long on a busy machine), and none is left behind."""

from __future__ import annotations

import asyncio
import os
from collections.abc import Iterator

import pytest

from plugnproduce import service
from plugnproduce.hmi import jobs, work
from plugnproduce.hmi.work import Work, WorkLimits
from tests.lines import WAIT
from tests.processes import _processes


def _started_here() -> list[int]:
    """The live processes this one started through multiprocessing: its fork server and the workers forked
    from it."""
    table = _processes()
    servers = {pid for pid, (ppid, state, cmd) in table.items()
               if ppid == os.getpid() and state != "Z" and "multiprocessing.forkserver" in cmd}
    return sorted(servers | {pid for pid, (ppid, state, _) in table.items() if ppid in servers and state != "Z"})


@pytest.fixture
def no_fork_server() -> Iterator[None]:
    """No fork server running when the test starts (the next starts with the preload the test sets), none left
    when it ends."""
    work._end_forkserver()
    yield
    work._end_forkserver()


async def _until(condition: object, what: str) -> None:
    async with asyncio.timeout(WAIT):
        while not condition():  # type: ignore[operator]
            await asyncio.sleep(0.05)


async def test_the_workers_stop_while_their_fork_server_is_still_preloading(
        no_fork_server: None, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(work, "PRELOAD", [*work.PRELOAD, "tests.hmi.slow_preload"])
    k = service.knowledge()
    starting_work = Work(WorkLimits(workers=2), k, service.catalogue(knowledge=k))
    starting = starting_work.start()
    await _until(_started_here, "the fork server started")
    assert not starting.done(), "the workers started, though their fork server never ends its preload"
    async with asyncio.timeout(WAIT):
        await starting_work.stop()
    assert _started_here() == []
    assert starting.done()
    monkeypatch.undo()  # the HMI's own preload again: a new application's workers start and work
    next_work = Work(WorkLimits(workers=1), k, service.catalogue(knowledge=k))
    try:
        pool = await next_work.start()
        assert await asyncio.wrap_future(pool.schedule(jobs.ready)) is None
        assert len(_started_here()) == 2  # a new fork server and the one worker
    finally:
        await next_work.stop()
    assert _started_here() == [pid for pid in _started_here() if "forkserver" in _processes()[pid][2]]

