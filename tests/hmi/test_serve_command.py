"""``pnp serve`` as a user starts it: it prints the URL and the token, serves, and stops on Ctrl-C."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import pytest
from typer.testing import CliRunner

from plugnproduce import controller, service
from plugnproduce.cli import app
from plugnproduce.protocols.upnp import private_network
from plugnproduce.sim.bin import SimulatedBin
from tests.hmi.conftest import TOKEN
from tests.lines import Lines

SERVE = [sys.executable, "-m", "plugnproduce", "serve", "--port", "0"]


def _start(*args: str, env: dict[str, str] | None = None) -> tuple[subprocess.Popen[str], Lines, list[str]]:
    proc = subprocess.Popen([*SERVE, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, **(env or {})})
    out = Lines(proc.stdout)
    try:
        lines = [out.next().strip()]  # comes once the server listens and says where
    except AssertionError:
        proc.kill()
        raise
    return proc, out, lines


def _stop(proc: subprocess.Popen[str], out: Lines, sig: signal.Signals = signal.SIGINT) -> str:
    proc.send_signal(sig)  # Ctrl-C by default
    try:
        code = proc.wait(timeout=60)
    finally:
        proc.kill()  # no effect once it has exited
    rest = "".join(out.rest())
    assert proc.stdout is not None and proc.stderr is not None
    err = proc.stderr.read()
    proc.stdout.close()
    proc.stderr.close()
    assert code == 0, err
    assert "Traceback" not in err and "CancelledError" not in err and "Cancel " not in err, err  # a quiet stop
    return rest


def test_serve_prints_the_url_and_a_new_token() -> None:
    proc, out, lines = _start("--sim")
    try:
        lines += [out.next().strip(), out.next().strip()]
        url = lines[0].rsplit(" ", 1)[1]
        token = lines[2].removeprefix("token: ")
        assert url.startswith("http://127.0.0.1:") and lines[1] == f"open {url}#token={token}"
        assert httpx.get(url + "api/cell").json()["name"] == "bin-picking"
        assert httpx.delete(url + "api/cell/devices/gripper").status_code == 401
        assert httpx.delete(url + "api/cell/devices/gripper",
                            headers={"Authorization": f"Bearer {token}"}).status_code == 200
        assert httpx.get(url, headers={"Host": "attacker.example"}).status_code == 400
    finally:
        rest = _stop(proc, out)
    assert rest.strip().endswith("stopped")


def test_serve_takes_the_token_from_a_file_and_the_cell_given(tmp_path: Path) -> None:
    token_file = tmp_path / "token"
    token_file.write_text(TOKEN + "\n")
    cell = Path(__file__).resolve().parents[2] / "descriptions" / "cells" / "assembly.yaml"
    proc, out, lines = _start("--sim", "--token-file", str(token_file), "--cell", str(cell))
    try:
        url = lines[0].rsplit(" ", 1)[1]
        assert httpx.get(url + "api/cell").json()["name"] == "assembly"
        res = httpx.post(url + "api/cell/devices", json={"device": "gripper"}, headers={"Authorization": f"Bearer {TOKEN}"})
        assert res.status_code == 200
    finally:
        rest = _stop(proc, out)
    assert TOKEN not in "".join(lines) + rest


def test_without_sim_the_cell_is_what_discovery_finds() -> None:
    proc, out, lines = _start(env={"PNP_SSDP_PORT": str(private_network().port)})
    try:
        url = lines[0].rsplit(" ", 1)[1]
        cell = httpx.get(url + "api/cell").json()
        assert (cell["name"], cell["devices"], cell["pluggable"]) == ("live", [], False)
    finally:
        _stop(proc, out)


def _finished(url: str, run_id: str) -> dict[str, object]:
    """The run's view once it has ended (waits as long as the run takes, up to the test's own timeout)."""
    with httpx.Client(timeout=120) as client:
        while (view := client.get(f"{url}api/runs/{run_id}").json())["status"] == "running":
            time.sleep(0.1)  # polling, not synchronisation: the loop ends on what the server says
    return view


def test_serve_sim_works_on_a_simulated_bin_of_the_given_parts() -> None:
    proc, out, lines = _start("--sim", "--bin-parts", "2", "--bin-seed", "3")
    try:
        lines += [out.next().strip(), out.next().strip()]
        url, token = lines[0].rsplit(" ", 1)[1], lines[2].removeprefix("token: ")
        yaml = (service.builtin("tasks") / "bin-picking-until-empty.yaml").read_bytes()
        task = httpx.post(url + "api/task/import", content=yaml, headers={"Content-Type": "application/yaml"},
                          timeout=120).json()
        res = httpx.post(url + "api/runs", json={"task": task}, headers={"Authorization": f"Bearer {token}"},
                         timeout=120)
        assert res.status_code == 202, res.text
        run_id = res.json()["run"]
        assert _finished(url, run_id)["status"] == "succeeded"
        journal = httpx.get(f"{url}api/runs/{run_id}/journal").json()
        found = [r["params"] for r in journal if r["kind"] == "event" and r["event"] == "PartLocalized"]
        placed = sorted(p.pose for p in SimulatedBin(2, 3).parts)
        assert [f["outcome"] for f in found] == ["PartFound", "PartFound", "BinEmpty"]
        assert sorted(f["part_pose"] for f in found[:2]) == placed  # the two parts of that bin, each once
    finally:
        _stop(proc, out)


def test_bin_parts_need_sim() -> None:
    result = CliRunner().invoke(app, ["serve", "--bin-parts", "3"])
    assert result.exit_code == 2
    assert result.output.strip() == "--bin-parts works on simulated devices: add --sim"


def test_faults_need_sim() -> None:
    result = CliRunner().invoke(app, ["serve", "--faults", "gripper:drop-response"])
    assert result.exit_code == 2
    assert result.output.strip() == "--faults needs --sim: faults are injected into simulated devices"


def test_a_missing_token_file_is_one_line_and_exit_2(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["serve", "--token-file", str(tmp_path / "none")])
    assert result.exit_code == 2
    assert result.output.strip() == f"{tmp_path / 'none'}: cannot read the token file: No such file or directory"


def _busy_task(rounds: int) -> dict[str, object]:
    steps = [{"command": "bin-pick", "params": {"grip_force": 45, "exposure": 25, "part_type": "bracket"}},
             {"command": "place", "params": {"place_pose": [0.6, -0.2, 0.1, 0, 180, 0], "speed": 80}}]
    return {"name": "busy", "steps": steps * 100, "repeat": rounds}


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_issue_15_serve_stops_on_a_signal_while_a_run_is_active(sig: signal.Signals) -> None:
    proc, out, lines = _start("--sim")
    lines += [out.next().strip(), out.next().strip()]
    url, token = lines[0].rsplit(" ", 1)[1], lines[2].removeprefix("token: ")
    res = httpx.post(url + "api/runs", json={"task": _busy_task(10)}, headers={"Authorization": f"Bearer {token}"},
                     timeout=120)
    assert res.status_code == 202 and res.json()["status"] == "running"
    assert _stop(proc, out, sig).strip().endswith("stopped")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_issue_15_serve_stops_on_a_signal_while_a_request_is_being_worked_on(sig: signal.Signals) -> None:
    proc, out, lines = _start("--sim")
    url = lines[0].rsplit(" ", 1)[1]
    sent = threading.Event()
    answers: list[httpx.Response] = []

    def check() -> None:
        with httpx.Client(timeout=120) as client, contextlib.suppress(httpx.HTTPError):
            sent.set()
            answers.append(client.post(url + "api/task/repair", json=_busy_task(10)))

    worker = threading.Thread(target=check, daemon=True)
    worker.start()
    sent.wait(10)
    assert _stop(proc, out, sig).strip().endswith("stopped")
    worker.join(60)
    for answer in answers:  # none when the request had not reached the server yet
        assert answer.status_code in (200, 503), answer.text
        assert answer.status_code == 200 or "the HMI is stopping" in answer.json()["detail"]


@pytest.mark.parametrize("checked", [False, True], ids=["workers-starting", "after-a-check"])
def test_issue_15_ctrl_c_at_the_terminal_stops_serve_and_its_workers_quietly(checked: bool) -> None:
    """Ctrl-C at a terminal reaches every process of the foreground group: the server's worker processes
    (and the server they are forked from) leave it to the server and print nothing."""
    proc = subprocess.Popen([*SERVE, "--sim"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)  # its own process group, as a terminal's foreground job
    out = Lines(proc.stdout)
    url = out.next().strip().rsplit(" ", 1)[1]
    assert httpx.get(url + "api/cell", timeout=120).status_code == 200  # serving; its workers may still start
    if checked:  # the workers are up and have worked
        step = _busy_task(1)["steps"][:2]  # type: ignore[index]
        res = httpx.post(url + "api/task/check", json={"name": "t", "steps": step}, timeout=120)
        assert res.status_code == 200 and res.json()["plausible"] is True
    os.killpg(proc.pid, signal.SIGINT)
    try:
        code = proc.wait(timeout=60)
    finally:
        proc.kill()
    assert proc.stderr is not None and proc.stdout is not None
    err = proc.stderr.read()
    proc.stdout.close()
    proc.stderr.close()
    assert code == 0, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert "".join(out.rest()).strip().endswith("stopped")


def test_serve_sim_gives_the_runs_of_a_localizing_task_a_default_bin_and_says_so() -> None:
    proc, out, lines = _start("--sim")
    try:
        lines += [out.next().strip(), out.next().strip(), out.next().strip()]
        assert lines[3] == ("simulated bin: 5 parts at random poses (seed 0) for the runs of tasks that loop on a "
                            "localized pose; --bin-parts N for another")
        url, token = lines[0].rsplit(" ", 1)[1], lines[2].removeprefix("token: ")
        auth = {"Authorization": f"Bearer {token}"}
        views = {}
        for name in ("bin-picking-until-empty", "bin-picking"):  # the fixed-pose task runs on the charts' values
            yaml = (service.builtin("tasks") / f"{name}.yaml").read_bytes()
            task = httpx.post(url + "api/task/import", content=yaml, headers={"Content-Type": "application/yaml"},
                              timeout=120).json()
            res = httpx.post(url + "api/runs", json={"task": task}, headers=auth, timeout=120)
            assert res.status_code == 202, res.text
            views[name] = (res.json()["run"], _finished(url, res.json()["run"])["status"])
        assert [status for _, status in views.values()] == ["succeeded", "succeeded"]
        journal = httpx.get(f"{url}api/runs/{views['bin-picking-until-empty'][0]}/journal").json()
        found = [r["params"] for r in journal if r["kind"] == "event" and r["event"] == "PartLocalized"]
        assert [f["outcome"] for f in found] == ["PartFound"] * 5 + ["BinEmpty"]
        assert sorted(f["part_pose"] for f in found[:-1]) == sorted(p.pose for p in SimulatedBin(5, 0).parts)
    finally:
        _stop(proc, out)


def test_issue_24_serve_takes_the_discovery_timeout_for_its_simulated_devices() -> None:
    # hmi/simcell.py waited a fixed 10 s: pnp serve --sim failed to start at load 18-20
    from plugnproduce.cli.serve import cell_source
    from plugnproduce.controller.simcell import SimulatedCellSource

    default = cell_source(None, sim=True)
    given = cell_source(None, sim=True, discovery_timeout=240.0)
    assert isinstance(default, SimulatedCellSource) and isinstance(given, SimulatedCellSource)
    assert (default._wait, given._wait) == (controller.SIMULATED_DISCOVERY_SECONDS, 240.0)
    help_text = CliRunner().invoke(app, ["serve", "--help"], terminal_width=200).stdout
    assert "--discovery-timeout SECONDS" in help_text
