"""Issue 15: expensive requests have a time budget, stop when their client goes away, and never keep the HMI
from answering other clients (a real server on a free loopback port; the server's log says when work stops)."""

from __future__ import annotations

import json
import logging
import socket
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx
import pytest
import uvicorn

from plugnproduce import service
from plugnproduce.hmi import ExecutorRunner, SimulatedCellSource, create_app
from plugnproduce.hmi.work import WorkLimits
from tests.hmi.conftest import TOKEN

SMALL = {"name": "small", "steps": [{"command": "bin-pick", "params": {"grip_force": 45, "exposure": 25}},
                                    {"command": "place"}]}
STEP = {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 9999}}
LONG = json.dumps({"name": "long", "steps": [STEP] * 1000}).encode()
"""The largest task the editor accepts: validating it takes many seconds, far longer than a small check."""
WAIT = 120.0
"""The most any step of these tests waits for the server (a bound on a hang, not a measured time)."""


class ServerLog(logging.Handler):
    """The lines the server writes about its work, and a way to wait for one."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.lines: list[str] = []
        self._changed = threading.Condition()

    def emit(self, record: logging.LogRecord) -> None:
        with self._changed:
            self.lines.append(record.getMessage())
            self._changed.notify_all()

    def wait_for(self, text: str) -> str:
        """The first line containing ``text``, once the server has written it."""
        with self._changed:
            found = self._changed.wait_for(lambda: next((x for x in self.lines if text in x), None), WAIT)
        assert found, f"the server never said {text!r}; it said {self.lines}"
        return found


@pytest.fixture()
def server_log() -> Iterator[ServerLog]:
    handler = ServerLog()
    logger = logging.getLogger("plugnproduce.hmi.work")
    level = logger.level
    logger.setLevel(logging.DEBUG)
    logger.addHandler(handler)
    try:
        yield handler
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


@contextmanager
def serving(tmp_path: Path, limits: WorkLimits) -> Iterator[tuple[str, int]]:
    """The HMI over the simulated bin-picking cell with these work limits, on a free loopback port."""
    source = SimulatedCellSource(service.cell(service.builtin("cells", "bin-picking.yaml")), service.catalogue())
    app = create_app(source, ExecutorRunner(source, tmp_path / "runs"), TOKEN, limits=limits)
    sock = socket.create_server(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on", ws="none",
                                           timeout_graceful_shutdown=1))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, name="hmi-server", daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{port}", port
    finally:
        app.state.hub.close_streams()
        server.should_exit = True
        thread.join(30)
        sock.close()


@contextmanager
def long_request(port: int, server_log: ServerLog) -> Iterator[socket.socket]:
    """A client that has sent the long validation and whose work the server has taken on; closed at the end."""
    client = socket.create_connection(("127.0.0.1", port), timeout=WAIT)
    head = (f"POST /api/task/validate HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(LONG)}\r\n\r\n").encode()
    client.sendall(head + LONG)
    server_log.wait_for("POST /api/task/validate: the validation scheduled")
    try:
        yield client
    finally:
        client.close()


def _unanswered(client: socket.socket) -> bool:
    client.setblocking(False)
    try:
        return client.recv(1) == b"x"  # pragma: no cover  (an answer, or b"" for a closed connection)
    except BlockingIOError:
        return True
    finally:
        client.setblocking(True)


def test_a_request_over_its_budget_ends_with_504_and_the_next_one_is_answered(
        tmp_path: Path, server_log: ServerLog) -> None:
    with serving(tmp_path, WorkLimits(seconds=2, workers=1, waiting=0)) as (url, _), \
            httpx.Client(base_url=url, timeout=WAIT) as client:
        res = client.post("/api/task/validate", content=LONG, headers={"content-type": "application/json"})
        assert res.status_code == 504
        assert res.json() == {"detail": "the validation took longer than 2 s; try a shorter task"}
        assert "over its budget of 2 s" in server_log.wait_for("POST /api/task/validate: the validation stopped")
        check = client.post("/api/task/check", json=SMALL)  # its worker was stopped and replaced
        assert check.status_code == 200 and check.json()["plausible"] is True


def test_a_client_that_goes_away_has_its_work_stopped_and_its_place_freed(
        tmp_path: Path, server_log: ServerLog) -> None:
    with serving(tmp_path, WorkLimits(seconds=600, workers=1, waiting=0)) as (url, port), \
            httpx.Client(base_url=url, timeout=WAIT) as client:
        with long_request(port, server_log):
            busy = client.post("/api/task/check", json=SMALL)
            assert busy.status_code == 503 and busy.headers["retry-after"] == "5"
            assert busy.json()["detail"].startswith("the HMI is busy with 1 checks, repairs and the like (at most 1 ")
        line = server_log.wait_for("POST /api/task/validate: the validation stopped")
        assert line.endswith("the client closed the connection")
        check = client.post("/api/task/check", json=SMALL)
        assert check.status_code == 200 and check.json()["plausible"] is True


def test_other_clients_are_answered_while_a_long_request_is_worked_on(tmp_path: Path, server_log: ServerLog) -> None:
    with serving(tmp_path, WorkLimits(workers=2, waiting=0)) as (url, port), \
            httpx.Client(base_url=url, timeout=WAIT) as client, long_request(port, server_log) as long:
        assert client.get("/api/cell").status_code == 200
        assert client.get("/api/commands").json()["offered"]
        check = client.post("/api/task/check", json=SMALL)
        assert check.status_code == 200 and check.json()["plausible"] is True
        assert _unanswered(long)  # the long validation is still being worked on


def test_a_request_over_its_memory_budget_ends_with_413(tmp_path: Path, server_log: ServerLog) -> None:
    with serving(tmp_path, WorkLimits(workers=1, waiting=0, memory=16 * 1024**2)) as (url, _), \
            httpx.Client(base_url=url, timeout=WAIT) as client:
        res = client.post("/api/task/validate", content=LONG, headers={"content-type": "application/json"})
        assert res.status_code == 413
        assert res.json() == {"detail": "the validation needed more than the 16 MiB of memory a request may use; "
                                        "try a shorter task"}
        assert "over its memory budget" in server_log.wait_for("POST /api/task/validate: the validation stopped")


def test_the_readme_gives_the_budgets_the_hmi_keeps() -> None:
    from plugnproduce.hmi.work import WAITING, WORK_MEMORY, WORK_SECONDS, WORKERS

    readme = " ".join((Path(__file__).parents[2] / "README.md").read_text(encoding="utf-8").split())
    words = {2: "two", 4: "four"}
    assert f"a budget of {WORK_SECONDS:g} s (then 504" in readme
    assert f"{WORK_MEMORY // 1024**2} MiB of memory (413)" in readme
    assert f"{words[WORKERS]} run at a time, {words[WAITING]} more may wait" in readme
