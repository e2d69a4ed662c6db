"""Through the HTTP API: a bug is a 500 saying so (the traceback goes to the server's log), while a name the
request got wrong is a 404 with the nearest known names; a ``KeyError`` no longer passes for either."""

from __future__ import annotations

import logging

import httpx
import pytest

from plugnproduce import service
from tests.hmi.conftest import AUTH


def _raise_key_error(*_: object) -> dict[str, object]:
    return {}["wrong-key"]  # type: ignore[no-any-return]


async def test_a_key_error_raised_by_a_bug_is_500_with_the_traceback_logged(
        client: httpx.AsyncClient, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.setattr(service, "device_view", _raise_key_error)
    with caplog.at_level(logging.ERROR, logger="plugnproduce.hmi"):
        res = await client.get("/api/catalogue", headers=AUTH)
    assert res.status_code == 500
    assert res.json() == {"detail": "error: a bug in plugnproduce, not a mistake in the input (KeyError: "
                                    "'wrong-key'); the traceback is in the server's log: please report it with "
                                    "that traceback"}
    assert res.headers["x-content-type-options"] == "nosniff"  # still inside the security headers
    [record] = [r for r in caplog.records if r.name == "plugnproduce.hmi"]
    assert record.getMessage() == "bug answering GET /api/catalogue"
    assert record.exc_info is not None and record.exc_info[0] is KeyError


async def test_the_server_goes_on_answering_after_a_bug(client: httpx.AsyncClient,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    with monkeypatch.context() as patched:
        patched.setattr(service, "device_view", _raise_key_error)
        assert (await client.get("/api/catalogue", headers=AUTH)).status_code == 500
    assert (await client.get("/api/catalogue", headers=AUTH)).status_code == 200


async def test_an_unknown_device_is_404_with_did_you_mean(client: httpx.AsyncClient) -> None:
    res = await client.get("/api/charts/device/griper.svg")
    assert res.status_code == 404 and res.json()["detail"] == (
        "error: unknown device 'griper'; did you mean gripper or vacuum-gripper?")


async def test_an_unknown_process_command_is_404_with_did_you_mean(client: httpx.AsyncClient) -> None:
    res = await client.get("/api/processes/plase")
    assert res.status_code == 404
    assert res.json()["detail"] == "error: unknown process command 'plase'; did you mean place?"
