"""The controller's user identity on OPC UA: a device whose server takes no anonymous session gets the user name
and password the users file gives it (``PNP_OPCUA_USERS``, else ``PKI/users``); without one, or with a wrong
one, it is refused in one line naming the device, the user and the file, never the password."""

from __future__ import annotations

from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest
from asyncua import Server, ua
from asyncua.crypto.permission_rules import User, UserRole

from plugnproduce.errors import ProtocolConnectionError, ProtocolError
from plugnproduce.protocols.opcua import OpcUaDeviceClient
from plugnproduce.protocols.opcua.security import Security, from_environment
from plugnproduce.protocols.opcua.spec import format_endpoint, namespace_for
from tests.lines import WAIT

DEVICE = "press"
PASSWORD = "s3cret pass"  # a password may hold spaces: the rest of its line


class _Operators:
    """Lets only the user ``operator`` with :data:`PASSWORD` open a session."""

    def get_user(self, iserver: Any, username: str | None = None, password: str | None = None,
                 certificate: Any = None) -> User | None:
        if username == "operator" and password == PASSWORD:
            return User(role=UserRole.User, name=username)
        return None


@pytest.fixture
async def press() -> AsyncIterator[str]:
    """A plain asyncua server of the device ``press`` (the naming rule's namespace, object and ``State``) that
    takes user names and passwords only, no anonymous session."""
    server = Server(user_manager=_Operators())
    await server.init()
    server.set_endpoint(format_endpoint("127.0.0.1", 0, f"/pnp/{DEVICE}"))
    server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    server.set_security_IDs(["Username"])
    idx = await server.register_namespace(namespace_for(DEVICE))
    device = await server.nodes.objects.add_object(idx, DEVICE)
    await device.add_variable(idx, "State", ua.Variant("Idle", ua.VariantType.String))
    await server.start()
    port = server.bserver._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
    try:
        yield format_endpoint("127.0.0.1", port, f"/pnp/{DEVICE}")
    finally:
        await server.stop()


def _users(tmp_path: Path, text: str) -> Path:
    users = tmp_path / "users"
    users.write_text(text)
    users.chmod(0o600)
    return users


async def test_the_user_of_the_users_file_opens_the_session(press: str, tmp_path: Path) -> None:
    """The device's own line, the ``*`` line, and the device's line before a ``*`` line."""
    for lines in (f"press operator {PASSWORD}\n", f"# every device\n\n* operator {PASSWORD}\n",
                  f"press operator {PASSWORD}\n* guest nothing\n"):
        client = await OpcUaDeviceClient.connect(press, DEVICE, WAIT, Security(users=_users(tmp_path, lines)))
        try:
            assert await client.state(WAIT) == "Idle", lines
        finally:
            await client.close()


async def test_no_user_for_the_device_is_refused_naming_it(press: str, tmp_path: Path) -> None:
    users = _users(tmp_path, f"lathe operator {PASSWORD}\n")
    for security in (Security(), Security(users=users)):
        with pytest.raises(ProtocolConnectionError) as refused:
            await OpcUaDeviceClient.connect(press, DEVICE, WAIT, security)
        assert str(refused.value) == (
            f"device press: cannot connect to {press} (security mode None): BadIdentityTokenRejected: the device "
            "asks for a user name and password; the users file gives none for it (PNP_OPCUA_USERS)")


async def test_a_wrong_password_is_refused_naming_the_device_the_user_and_the_file(press: str,
                                                                                   tmp_path: Path) -> None:
    users = _users(tmp_path, "press operator wrong-one\n")
    with pytest.raises(ProtocolConnectionError) as refused:
        await OpcUaDeviceClient.connect(press, DEVICE, WAIT, Security(users=users))
    assert str(refused.value) == (f"device press: cannot connect to {press} (security mode None): "
                                  f"BadUserAccessDenied: the device refused the user 'operator' of {users}")
    assert "wrong-one" not in str(refused.value) and "wrong-one" not in repr(refused.value.__cause__)


async def test_a_bad_users_file_is_one_line_with_its_line(tmp_path: Path) -> None:
    """Said before any connection (nothing listens at the endpoint)."""
    press = f"opc.tcp://127.0.0.1:1/pnp/{DEVICE}"
    users = _users(tmp_path, f"# devices\npress operator {PASSWORD}\nlathe-only-a-name\n")
    with pytest.raises(ProtocolError, match=rf"^{users}:3: expected DEVICE USER PASSWORD \(DEVICE may be \*\)$"):
        await OpcUaDeviceClient.connect(press, DEVICE, WAIT, Security(users=users))
    with pytest.raises(ProtocolError, match=f"^{tmp_path / 'none'}: cannot read the OPC UA users file"):
        await OpcUaDeviceClient.connect(press, DEVICE, WAIT, Security(users=tmp_path / "none"))


def test_the_users_file_comes_from_the_environment_or_the_pki_folder(tmp_path: Path) -> None:
    assert from_environment({"PNP_OPCUA_USERS": str(tmp_path / "mine")}).users == tmp_path / "mine"
    assert from_environment({"PNP_OPCUA_PKI": str(tmp_path)}).users is None
    _users(tmp_path, "* a b\n")
    assert from_environment({"PNP_OPCUA_PKI": str(tmp_path)}).users == tmp_path / "users"
    assert from_environment({"PNP_OPCUA_PKI": str(tmp_path), "PNP_OPCUA_USERS": "x"}).users == Path("x")
