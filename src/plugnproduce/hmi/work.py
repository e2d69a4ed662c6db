"""Expensive requests run in worker processes, each under a time and memory budget, and stop with their client.

Checking, validating, repairing, explaining and generating a task (and reading a task file) run the
reasoners, which may take long on a large task and cannot be interrupted from another thread. So
each such request runs as a job (:mod:`plugnproduce.hmi.jobs`) in a pool of worker processes
(``pebble.ProcessPool``) and the server's event loop only waits for it:

- a job that runs longer than its budget is stopped (its worker is killed and replaced) and the
  request ends with 504 and ``"the check took longer than 120 s; try a shorter task"``;
- a job that needs more memory than its budget ends with 413;
- when the client closes the connection, its job is stopped at once;
- at most ``workers`` jobs run at a time and ``waiting`` more wait for a worker; a request beyond
  that is refused with 503 and ``Retry-After`` instead of joining an endless queue;
- cheap requests (the cell, the offered commands, the processes) never wait for a job.

Each stopped job is logged on the ``plugnproduce.hmi.work`` logger (a warning for a budget, info for
a client that went away).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import multiprocessing
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing import forkserver
from typing import Any, TypeVar

from fastapi import HTTPException, Request, status
from pebble import ProcessExpired, ProcessPool

from plugnproduce.hmi import jobs
from plugnproduce.service import DeviceDescription, Knowledge

log = logging.getLogger(__name__)

T = TypeVar("T")

WORK_SECONDS = 120.0
"""The time budget of one expensive request, counted from when a worker starts on it. The largest task
the editor accepts (1,000 steps) validates in about 16 s on an idle two-core machine."""

WORKERS = 2
"""Expensive requests worked on at a time (one worker process each)."""

WAITING = 4
"""Expensive requests that may wait for a worker; one more is refused (503) until one ends."""

WORK_MEMORY = 2 * 1024**3
"""The address space one request's job may use, in bytes, beyond what its worker process uses when it starts
(about 110 MiB); a job over it ends with 413. Validating the largest task the editor accepts uses about 45 MiB."""

PRELOAD = ["plugnproduce.hmi.jobs", "plugnproduce.validation", "networkx", "pyshacl"]
"""Modules every worker starts with (imported once, before any worker is forked), so that no request
pays for importing them."""

RETRY_AFTER = "5"
"""Seconds a refused client is told to wait before it asks again."""


@dataclass(frozen=True)
class _Asked:
    """One expensive request: what it asks for ("the check"), where ("POST /api/task/check"), and what to
    advise when it is over its budget."""

    what: str
    where: str
    advice: str


@dataclass(frozen=True)
class WorkLimits:
    """How much work the HMI takes on: the budget per request, the workers, the queue and the memory."""

    seconds: float = WORK_SECONDS
    workers: int = WORKERS
    waiting: int = WAITING
    memory: int | None = WORK_MEMORY


class Work:
    """The pool of worker processes the expensive requests of one HMI application run in.

    Used from the server's event loop only (no locks): a request holds its place from when it is
    accepted until it ends, and a job is stopped when its request ends, whatever ended it.
    """

    def __init__(self, limits: WorkLimits, knowledge: Knowledge, catalogue: list[DeviceDescription]) -> None:
        self.limits = limits
        self._knowledge = knowledge
        self._catalogue = catalogue
        self._starting: asyncio.Future[ProcessPool] | None = None
        self._jobs: set[concurrent.futures.Future[Any]] = set()
        self._active = 0
        self._waiting: set[asyncio.Future[ProcessPool]] = set()

    @property
    def active(self) -> int:
        """Expensive requests running or waiting for a worker."""
        return self._active

    def start(self) -> asyncio.Future[ProcessPool]:
        """Start the worker processes in the background (each is given the knowledge and the catalogue once);
        the first expensive request waits for them. Call on the server's event loop."""
        if self._starting is None:
            _start_forkserver()
            self._starting = asyncio.ensure_future(asyncio.to_thread(self._new_pool))
        return self._starting

    def _new_pool(self) -> ProcessPool:
        """The pool, its workers started (in this thread, not with the first request)."""
        pool = ProcessPool(self.limits.workers, initializer=jobs.start_worker,
                           initargs=(self._knowledge, self._catalogue, self.limits.memory), context=_context())
        pool.schedule(jobs.ready)
        return pool

    async def _pool(self) -> ProcessPool:
        return await asyncio.shield(self.start())

    async def stop(self) -> None:
        """Stop every job and the worker processes."""
        self.cancel_all()
        starting, self._starting = self._starting, None
        if starting is not None:
            pool = await starting
            pool.stop()  # type: ignore[no-untyped-call]  # pebble leaves it unannotated
            await asyncio.to_thread(pool.join)

    def cancel_all(self) -> None:
        """Stop every job in progress; each of their requests ends with 503 (the server is stopping)."""
        for waiting in list(self._waiting):
            waiting.cancel()
        for job in list(self._jobs):
            job.cancel()

    async def run(self, request: Request, what: str, function: Callable[..., T], *args: Any,
                  advice: str = "try a shorter task") -> T:
        """Run ``function(*args)`` in a worker within the budget; ``what`` names the work in messages
        ("the check"), ``advice`` says what to do when it is over its budget. Stops the job when its client
        disconnects."""
        if self._active >= self.limits.workers + self.limits.waiting:
            raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE,
                                f"the HMI is busy with {self._active} checks, repairs and the like "
                                f"(at most {self.limits.workers} at a time and {self.limits.waiting} waiting); "
                                "try again in a moment", headers={"Retry-After": RETRY_AFTER})
        self._active += 1
        try:
            return await self._job(_Asked(what, f"{request.method} {request.url.path}", advice), request,
                                   function, args)
        finally:
            self._active -= 1

    async def _job(self, asked: _Asked, request: Request, function: Callable[..., T], args: tuple[Any, ...]) -> T:
        waiting = asyncio.ensure_future(self._pool())
        self._waiting.add(waiting)
        try:
            pool = await waiting
        except asyncio.CancelledError:  # the server stops while the workers start
            raise _stopping(asked.what) from None
        finally:
            self._waiting.discard(waiting)
        job: concurrent.futures.Future[T] = pool.schedule(jobs.call, (function, *args), timeout=self.limits.seconds)
        self._jobs.add(job)
        log.debug("%s: %s scheduled", asked.where, asked.what)
        started = time.monotonic()
        try:
            return await self._outcome(asked, request, job)
        finally:
            job.cancel()  # no effect once it has ended; stops it if this request was cancelled
            self._jobs.discard(job)
            log.debug("%s: %s ended after %.1f s", asked.where, asked.what, time.monotonic() - started)

    async def _outcome(self, asked: _Asked, request: Request, job: concurrent.futures.Future[T]) -> T:
        result = asyncio.wrap_future(job)
        gone = asyncio.ensure_future(_disconnected(request))
        either: set[asyncio.Future[Any]] = {result, gone}
        try:
            done, _ = await asyncio.wait(either, return_when=asyncio.FIRST_COMPLETED)
        except asyncio.CancelledError:  # the server stops: end this request quietly, its job with it
            job.cancel()
            raise _stopping(asked.what) from None
        finally:
            gone.cancel()
        if result not in done:
            job.cancel()
            log.info("%s: %s stopped: the client closed the connection", asked.where, asked.what)
            raise _stopping(asked.what)
        return self._answer(asked, result)

    def _answer(self, asked: _Asked, result: asyncio.Future[T]) -> T:
        """The job's result, or its error as the HTTP error a client is told."""
        try:
            return result.result()
        except (asyncio.CancelledError, concurrent.futures.CancelledError):
            raise _stopping(asked.what) from None
        except TimeoutError as exc:
            if exc.__cause__ is not None:  # raised by the job itself (with its remote traceback), not the budget
                raise
            log.warning("%s: %s stopped: over its budget of %g s", asked.where, asked.what, self.limits.seconds)
            raise HTTPException(status.HTTP_504_GATEWAY_TIMEOUT,
                                f"{asked.what} took longer than {self.limits.seconds:g} s; {asked.advice}") from None
        except (jobs.OverMemory, MemoryError):
            log.warning("%s: %s stopped: over its memory budget", asked.where, asked.what)
            raise HTTPException(status.HTTP_413_CONTENT_TOO_LARGE,
                                f"{asked.what} needed more than the {_mib(self.limits.memory)} MiB of memory "
                                f"a request may use; {asked.advice}") from None
        except ProcessExpired as exc:
            log.warning("%s: %s stopped: its worker ended with code %s", asked.where, asked.what, exc.exitcode)
            raise HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE,
                                f"{asked.what} stopped: its worker process ended (code {exc.exitcode}); "
                                f"try again, or {asked.advice}") from None


def _context() -> multiprocessing.context.ForkServerContext:
    """Workers are forked from a clean, single-threaded fork server that has imported :data:`PRELOAD`."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(PRELOAD)
    return context


def _start_forkserver() -> None:
    """Start the fork server with Ctrl-C ignored, which it and every worker forked from it keep: a Ctrl-C at
    the terminal is for the server, which then stops its workers (multiprocessing's resource tracker ignores
    it the same way). Only the main thread may change how a signal is handled; elsewhere the fork server
    starts with the first pool as usual."""
    if threading.current_thread() is not threading.main_thread():
        return
    _context()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, previous)


async def _disconnected(request: Request) -> None:
    """Return when the client has closed the connection (the request's body has been read by then)."""
    while True:
        message = await request.receive()
        if message["type"] == "http.disconnect":
            return


def _stopping(what: str) -> HTTPException:
    return HTTPException(status.HTTP_503_SERVICE_UNAVAILABLE, f"{what} was stopped: the HMI is stopping "
                         "or the client went away", headers={"Retry-After": RETRY_AFTER})


def _mib(limit: int | None) -> str:
    return "unlimited" if limit is None else f"{limit // 1024**2:,}"


def work_of(request: Request) -> Work:
    """Dependency: the application's pool of workers for expensive requests."""
    work: Work = request.app.state.work
    return work
