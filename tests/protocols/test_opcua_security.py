"""OPC UA security at the device-facing edge: mode None only on loopback, Sign and SignAndEncrypt with the
certificates of a PKI folder, untrusted certificates refused on both sides."""

from __future__ import annotations

import asyncio
import shutil
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest

from plugnproduce import service
from plugnproduce.description.loader import load_device
from plugnproduce.errors import ProtocolConnectionError, ProtocolError
from plugnproduce.ontology.taxonomy import load_taxonomy
from plugnproduce.protocols.opcua import OpcUaDeviceClient
from plugnproduce.protocols.opcua.security import Security, from_environment, generate
from plugnproduce.sim.device import SimulatedDevice
from tests.lines import WAIT

DEVICE = "screwdriver-ua"


async def _device(pki: Path, mode: str, monkeypatch: pytest.MonkeyPatch) -> SimulatedDevice:
    monkeypatch.setenv("PNP_OPCUA_PKI", str(pki))
    monkeypatch.setenv("PNP_OPCUA_SECURITY", mode)
    device = SimulatedDevice(load_device(Path(service.builtin("devices", f"{DEVICE}.ttl")), load_taxonomy()))
    await device.start()
    return device


@pytest.fixture
async def signed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[SimulatedDevice]:
    device = await _device(tmp_path / "pki", "Sign", monkeypatch)
    try:
        yield device
    finally:
        await device.stop()


async def _screw(endpoint: str, security: Security) -> dict[str, Any]:
    """Run the screwing skill through our client: Start(Torque), then the Completed event's values."""
    client = await OpcUaDeviceClient.connect(endpoint, DEVICE, WAIT, security)
    done: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
    try:
        await client.subscribe(["Completed"], lambda _name, values: done.done() or done.set_result(values),
                               lambda _: None, lambda _: None, WAIT)
        assert await client.state(WAIT) == "Idle"
        await client.call("Start", {"Torque": 4.5}, WAIT)
        return await asyncio.wait_for(done, WAIT)
    finally:
        await client.close()


@pytest.mark.parametrize("mode", ["Sign", "SignAndEncrypt"])
async def test_the_skill_runs_over_sign_and_over_sign_and_encrypt(mode: str, tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """The simulated device makes the folder's certificates (its own and the controller's, each trusted by
    the other side); the controller's client runs the skill over the one mode the device offers."""
    pki = tmp_path / "pki"
    device = await _device(pki, mode, monkeypatch)
    try:
        assert {p.relative_to(pki).as_posix() for p in pki.rglob("*.der")} == {
            "own/cert.der", "clients/controller.der", f"devices/{DEVICE}/cert.der", f"trusted/{DEVICE}.der"}
        assert await _screw(device.endpoint, from_environment()) == {"achieved_torque": 4.5}
    finally:
        await device.stop()


async def test_a_client_without_a_certificate_is_refused_by_a_device_that_asks_for_one(
        signed: SimulatedDevice) -> None:
    with pytest.raises(ProtocolConnectionError, match=f"device {DEVICE}: cannot connect to .* \\(security mode "
                                                      "None\\): the device offers no endpoint with security mode "
                                                      "None"):
        await OpcUaDeviceClient.connect(signed.endpoint, DEVICE, WAIT, Security())


async def test_an_untrusted_device_certificate_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The device trusts the controller, but the controller's own folder trusts no device: the device's
    certificate is refused by the controller, said in words."""
    mine, pki = tmp_path / "mine", tmp_path / "pki"
    await generate(mine, [])
    (pki / "clients").mkdir(parents=True)
    shutil.copyfile(mine / "own" / "cert.der", pki / "clients" / "mine.der")
    device = await _device(pki, "Sign", monkeypatch)
    try:
        with pytest.raises(ProtocolConnectionError, match=f"device {DEVICE}: cannot connect to .*: "
                                                          "BadCertificateUntrusted: its certificate is not among "
                                                          "the trusted ones \\(PKI/trusted\\)$"):
            await OpcUaDeviceClient.connect(device.endpoint, DEVICE, WAIT, Security("Sign", mine))
    finally:
        await device.stop()


async def test_a_controller_certificate_the_device_does_not_trust_is_refused(signed: SimulatedDevice,
                                                                             tmp_path: Path) -> None:
    """The controller trusts the device, but the device does not know the controller's certificate."""
    mine = tmp_path / "mine"
    await generate(mine, [])
    shutil.copyfile(tmp_path / "pki" / "trusted" / f"{DEVICE}.der", mine / "trusted" / f"{DEVICE}.der")
    with pytest.raises(ProtocolConnectionError, match=f"device {DEVICE}: cannot connect to .*: "
                                                      "BadCertificateUntrusted: the device refused the controller's "
                                                      "certificate"):
        await OpcUaDeviceClient.connect(signed.endpoint, DEVICE, WAIT, Security("Sign", mine))


@pytest.mark.parametrize("endpoint", ["opc.tcp://192.0.2.7:4840/pnp/d", "opc.tcp://cell-a.example:4840/pnp/d"])
async def test_security_mode_none_off_loopback_is_refused_before_any_connection(endpoint: str) -> None:
    with pytest.raises(ProtocolError, match=f"^device d: {endpoint} is not on loopback and security mode None "
                                            "would send in the clear; set PNP_OPCUA_PKI .* PNP_OPCUA_ALLOW_INSECURE=1$"):
        await OpcUaDeviceClient.connect(endpoint, "d", WAIT, Security())


async def test_the_explicit_opt_in_lets_mode_none_leave_loopback() -> None:
    """With PNP_OPCUA_ALLOW_INSECURE=1 the controller tries the connection (here to a port nobody listens on
    of a documentation address, refused or timed out, but not by the loopback rule)."""
    security = from_environment({"PNP_OPCUA_ALLOW_INSECURE": "1"})
    with pytest.raises(ProtocolError) as caught:
        await OpcUaDeviceClient.connect("opc.tcp://192.0.2.7:4840/pnp/d", "d", 0.2, security)
    assert "not on loopback" not in str(caught.value)


@pytest.mark.parametrize(("env", "says"), [({"PNP_OPCUA_SECURITY": "Sign"}, "needs a PKI folder"),
                                           ({"PNP_OPCUA_SECURITY": "Basic128"}, "mode 'Basic128' is unknown")])
def test_a_bad_security_setting_is_one_clear_line(env: dict[str, str], says: str) -> None:
    with pytest.raises(ProtocolError, match=says):
        from_environment(env)


async def test_a_folder_without_the_controllers_certificate_is_named(tmp_path: Path) -> None:
    with pytest.raises(ProtocolError, match="own/cert.der: no controller certificate"):
        await OpcUaDeviceClient.connect("opc.tcp://127.0.0.1:4840/pnp/d", "d", WAIT, Security("Sign", tmp_path))
