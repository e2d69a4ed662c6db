"""OPC UA's standard address space, kept in the cache folder: a server started from it serves what a server
built fresh serves, each server has its own copy, and a kept file that cannot be read is built again."""

from __future__ import annotations

import pickle
from collections.abc import AsyncIterator, Callable
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Server, ua

from plugnproduce.protocols.opcua import space
from tests.lines import WAIT

_TYPES = (ua.ObjectIds.Double, ua.ObjectIds.Int64, ua.ObjectIds.Boolean, ua.ObjectIds.String,
          ua.ObjectIds.BaseDataType, ua.ObjectIds.BaseEventType, ua.ObjectIds.Argument)
"""The standard types the device servers use: argument data types, the events' base type, method arguments."""


@pytest.fixture(autouse=True)
def _no_copy_in_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test starts as a new process does: nothing read yet."""
    monkeypatch.setattr(space, "_kept", {})


@pytest.fixture(scope="module")
def kept_by_another(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The kept file as a first process (this module's first test) builds and writes it."""
    folder = tmp_path_factory.mktemp("kept")
    saved, space._kept = space._kept, {}
    try:
        space.standard_nodes(folder)  # builds and keeps
    finally:
        space._kept = saved
    return space.kept_file(folder).read_bytes()


def _kept_in(folder: Path, kept: bytes) -> Path:
    """``folder`` with the kept file an earlier process wrote."""
    path = space.kept_file(folder)
    path.write_bytes(kept)
    return path


def _kept_only(folder: Path, kept: bytes) -> dict[ua.NodeId, Any]:
    """The standard nodes as a new process reads them from ``folder`` (kept there by an earlier one)."""
    nodes = space._read(_kept_in(folder, kept))
    assert nodes is not None, "the kept file is not read back"
    return nodes[1]


def _summary(nodes: dict[ua.NodeId, Any]) -> dict[ua.NodeId, tuple[Any, ...]]:
    """Per node: its attributes' values (not their time stamps) and its references."""
    return {nodeid: (sorted((int(a), repr(v.value.Value if v.value is not None else None))
                            for a, v in data.attributes.items()),
                     sorted(repr(r) for r in data.references))
            for nodeid, data in nodes.items()}


def test_the_kept_space_holds_the_nodes_asyncua_builds(tmp_path: Path, kept_by_another: bytes) -> None:
    kept = _kept_only(tmp_path, kept_by_another)
    fresh = space._built()
    assert len(kept) == len(fresh) > space.MIN_NODES
    assert _summary(kept) == _summary(fresh)


def test_each_server_has_its_own_copy(tmp_path: Path, kept_by_another: bytes) -> None:
    _kept_in(tmp_path, kept_by_another)
    first = space.standard_nodes(tmp_path)
    namespaces = ua.NodeId(ua.ObjectIds.Server_NamespaceArray)
    first[namespaces].attributes[ua.AttributeIds.Value].value = ua.DataValue(ua.Variant(["changed"]))
    del first[ua.NodeId(ua.ObjectIds.BaseEventType)]
    second = space.standard_nodes(tmp_path)  # this process's copy, read from memory
    assert ua.NodeId(ua.ObjectIds.BaseEventType) in second
    assert second[namespaces].attributes[ua.AttributeIds.Value].value != first[namespaces].attributes[
        ua.AttributeIds.Value].value


async def test_what_one_server_adds_is_not_in_the_next(tmp_path: Path, kept_by_another: bytes) -> None:
    _kept_in(tmp_path, kept_by_another)
    first = await space.new_server(tmp_path)
    await first.register_namespace("urn:first")  # changes the namespace array's list in place
    await first.nodes.objects.add_object(2, "OnlyInTheFirst")
    second = await space.new_server(tmp_path)
    assert "urn:first" in await first.get_namespace_array()
    assert "urn:first" not in await second.get_namespace_array()
    names = [(await c.read_browse_name()).Name for c in await second.nodes.objects.get_children()]
    assert "Server" in names and "OnlyInTheFirst" not in names


async def _served(server: Server) -> dict[str, Any]:
    """What a plain client browses and reads of the standard nodes."""
    server.set_endpoint("opc.tcp://127.0.0.1:0/space")
    server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
    await server.start()
    try:
        port = server.bserver._server.sockets[0].getsockname()[1]
        async with Client(f"opc.tcp://127.0.0.1:{port}/space", timeout=WAIT) as client:
            seen: dict[str, Any] = {}
            for name, nodeid in (("Server", ua.ObjectIds.Server), ("ServerStatus", ua.ObjectIds.Server_ServerStatus),
                                 *((str(t), t) for t in _TYPES)):
                node = client.get_node(ua.NodeId(nodeid))
                children = [(await c.read_browse_name()).to_string() for c in await node.get_children()]
                seen[name] = ((await node.read_browse_name()).to_string(), await node.read_node_class(), sorted(children))
            seen["namespaces"] = await client.get_namespace_array()
            seen["state"] = await client.get_node(ua.NodeId(ua.ObjectIds.Server_ServerStatus_State)).read_value()
            return seen
    finally:
        await server.stop()


@pytest.fixture
async def fresh_server() -> AsyncIterator[Server]:
    server = Server()
    await server.init()  # asyncua building its standard space itself
    yield server


async def test_a_server_from_the_kept_space_serves_what_a_fresh_one_serves(
        tmp_path: Path, kept_by_another: bytes, fresh_server: Server, monkeypatch: pytest.MonkeyPatch) -> None:
    _kept_in(tmp_path, kept_by_another)  # this process reads the file, and builds nothing
    monkeypatch.setattr(space, "_built", lambda: pytest.fail("built again, though kept"))
    kept = await _served(await space.new_server(tmp_path))
    fresh = await _served(fresh_server)
    assert kept == fresh
    assert "0:ServerStatus" in kept["Server"][2] and "0:CurrentTime" in kept["ServerStatus"][2]
    assert {"0:EventId", "0:Message", "0:Severity", "0:SourceNode"} <= set(kept[str(ua.ObjectIds.BaseEventType)][2])
    assert kept["namespaces"][0] == "http://opcfoundation.org/UA/"
    assert kept["state"] == ua.ServerState.Running


def _garbage(path: Path) -> None:
    path.write_bytes(b"not a pickle at all")


def _truncated(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def _a_space_without_the_server(path: Path) -> None:
    nodes = pickle.loads(path.read_bytes())  # noqa: S301 - written by this test
    del nodes[ua.NodeId(ua.ObjectIds.Server)]
    path.write_bytes(pickle.dumps(nodes))


@pytest.mark.parametrize("spoil", [_garbage, _truncated, _a_space_without_the_server])
async def test_a_kept_file_that_cannot_be_read_is_built_again(tmp_path: Path, kept_by_another: bytes,
                                                              spoil: Callable[[Path], None]) -> None:
    path = _kept_in(tmp_path, kept_by_another)
    spoil(path)
    served = await _served(await space.new_server(tmp_path))
    assert "0:ServerStatus" in served["Server"][2]
    assert space._read(path) is not None, "the kept file is not rewritten"


def test_a_folder_that_cannot_be_written_only_costs_the_build(tmp_path: Path) -> None:
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder")
    nodes = space.standard_nodes(blocked / "cache")
    assert ua.NodeId(ua.ObjectIds.Server) in nodes
    assert not (blocked / "cache").exists()
