"""OPC UA's standard address space, built once and kept, so that a server starts without building it again.

Every asyncua server starts by filling its address space with the standard nodes of OPC UA (about 5,800: the
Server object, its status, the types), which costs one to two seconds of CPU per server: each simulated OPC UA
device and each Local Discovery Server pays it, so a mixed cell starts seconds later than it needs to. asyncua's
own remedy (a ``shelve`` file) needs a dbm module that not every Python has.

Here the standard nodes are built once and kept as a pickle in the user's cache folder (``opcuaspace-KEY.pickle``),
named by asyncua's version and where it is installed and by the Python version, so another asyncua or Python never
reads it. A process reads the file once and gives each server it starts its own copy (about a sixth of the build's
CPU time: the nodes' immutable parts, such as status codes and node ids, are kept once per copy rather than once per
use, which also leaves the garbage collector less to walk); a file that cannot be read, is too large or does not
hold a standard address space is built again and rewritten (whole and at once: a process starting beside it reads
the old file or the new one). The folder is the user's own (as for the parsed knowledge), so the pickle is as
trusted as the user's files. A folder that cannot be written only costs the next start the build.
"""

from __future__ import annotations

import contextlib
import copyreg
import dataclasses
import enum
import functools
import io
import os
import pickle
import sys
from pathlib import Path
from typing import Any

import asyncua
from asyncua import Server, ua
from asyncua.server.address_space import AddressSpace, NodeData, NodeManagementService
from asyncua.server.internal_server import InternalServer
from asyncua.server.standard_address_space import standard_address_space

from plugnproduce import folders
from plugnproduce.collector import paused
from plugnproduce.digests import sha256

FORMAT = 4
"""The layout of what is kept; another layout is another file name."""
KEEP = 2
"""Kept address spaces left in the cache folder (one per asyncua and Python in use); older ones are removed."""
MAX_BYTES = 64 * 2**20
"""A kept file larger than this (the standard space is about 10 MB) is not read but built again."""
_MARKS = (ua.ObjectIds.RootFolder, ua.ObjectIds.Server, ua.ObjectIds.Server_ServerStatus,
          ua.ObjectIds.Server_NamespaceArray, ua.ObjectIds.BaseEventType, ua.ObjectIds.BaseDataType)
"""Nodes a standard address space has, whatever else it has."""
MIN_NODES = 1000
"""Fewer nodes than this is not a standard address space."""

_kept: dict[Path, bytes] = {}
"""Per cache file, the pickled standard nodes this process read or built (each server unpickles its own copy)."""


def kept_file(folder: Path | None = None) -> Path:
    """The cache file of the standard address space for the installed asyncua and this Python."""
    source = standard_address_space.__file__ or ""
    stamp = f"{FORMAT}\0{sys.version}\0{asyncua.__version__}\0{source}\0{os.stat(source).st_mtime_ns}"
    key = sha256(stamp.encode()).hexdigest()[:16]
    return (folder or folders.cache_folder()) / f"opcuaspace-{key}.pickle"


def _built() -> dict[ua.NodeId, NodeData]:
    """The standard nodes, built as asyncua builds them (from the code it generated from the OPC UA node set)."""
    space = AddressSpace()
    with paused():
        standard_address_space.fill_address_space(NodeManagementService(space))
    nodes: dict[ua.NodeId, NodeData] = space._nodes
    return nodes


_OWN = ("__reduce_ex__", "__reduce__", "__getstate__", "__setstate__", "__slots__", "__getnewargs__",
        "__getnewargs_ex__")
"""What a class defines when it pickles in its own way."""


@functools.cache
def _plain(cls: type) -> bool:
    """Whether ``cls`` is one of asyncua's plain, changeable classes: no frozen dataclass, enum or class of its own
    pickling."""
    return (cls.__module__.startswith("asyncua.") and not issubclass(cls, (type, enum.Enum)) and not _frozen(cls)
            and not any(name in vars(base) for base in cls.__mro__[:-1] for name in _OWN))


class _Pickler(pickle.Pickler):
    """Pickles asyncua's plain objects so that unpickling sets their attributes one by one, as their constructors
    do: pickle's default fills each object's ``__dict__`` instead, which makes it a dictionary of its own, one more
    object for the garbage collector to walk; with some 300,000 of them, every later collection of the process
    walks twice as much."""

    def reducer_override(self, obj: Any) -> Any:
        cls = type(obj)
        if _plain(cls) and hasattr(obj, "__dict__"):  # type: ignore[arg-type]
            return copyreg.__newobj__, (cls,), (None, obj.__dict__)  # type: ignore[attr-defined]
        return NotImplemented


def _frozen(cls: type) -> bool:
    return dataclasses.is_dataclass(cls) and bool(cls.__dataclass_params__.frozen)  # type: ignore[attr-defined]


def _shared(value: Any, one: dict[tuple[type, str], Any]) -> Any:
    """``value`` with each immutable part (a frozen dataclass: node ids, names, values, status codes) replaced by the
    first one of its class that reads the same. asyncua makes a new one for each use, and a copy read back would
    make each anew: 70,000 status codes where a few differ, each one more object for the garbage collector."""
    cls = type(value)
    if _frozen(cls):
        try:
            hash(value)
        except TypeError:  # holds something changeable (a list): its own
            return value
        return one.setdefault((cls, repr(value)), value)  # by repr: a NodeId equals a NumericNodeId of its number
    if cls is list:
        value[:] = [_shared(v, one) for v in value]
    elif cls is dict:
        for key, v in value.items():
            value[key] = _shared(v, one)
    elif cls.__module__.startswith("asyncua.") and hasattr(value, "__dict__") and not isinstance(value, type):
        for key, v in vars(value).items():
            vars(value)[key] = _shared(v, one)
    return value


def _dumps(nodes: dict[ua.NodeId, NodeData]) -> bytes:
    out = io.BytesIO()
    with paused():
        _Pickler(out, protocol=pickle.HIGHEST_PROTOCOL).dump(_shared(nodes, {}))
    return out.getvalue()


def _fits(nodes: Any) -> bool:
    """Whether ``nodes`` is a standard address space: node ids to nodes, the standard marks among them."""
    return (isinstance(nodes, dict) and len(nodes) >= MIN_NODES
            and all(isinstance(k, ua.NodeId) and isinstance(v, NodeData) and v.nodeid == k for k, v in nodes.items())
            and all(ua.NodeId(mark) in nodes for mark in _MARKS))


def _read(path: Path) -> tuple[bytes, dict[ua.NodeId, NodeData]] | None:
    """The kept file's bytes and nodes, or None if it is missing, too large or not a standard address space."""
    try:
        if path.stat().st_size > MAX_BYTES:
            return None
        data = path.read_bytes()
        with paused():
            nodes = pickle.loads(data)  # noqa: S301 - the user's own cache folder, named by the asyncua it holds
    except Exception:  # noqa: BLE001 - a kept file that cannot be read, whatever the reason, is built again
        return None
    return (data, nodes) if _fits(nodes) else None


def standard_nodes(folder: Path | None = None) -> dict[ua.NodeId, NodeData]:
    """A fresh copy of OPC UA's standard nodes, for one server: read from the cache folder (or from this process's
    copy of it) when kept there, else built and kept."""
    path = kept_file(folder)
    data = _kept.get(path)
    if data is not None:
        with paused():
            return pickle.loads(data)  # type: ignore[no-any-return]  # noqa: S301 - pickled by this process
    found = _read(path)
    if found is not None:
        _kept[path] = found[0]
        return found[1]
    nodes = _built()
    data = _dumps(nodes)
    _kept[path] = data
    with contextlib.suppress(OSError):  # a folder that cannot be written only costs the next process the build
        folders.keep_newest(path, data, KEEP)
    return nodes


class _KeptSpaceServer(InternalServer):  # type: ignore[misc]
    """asyncua's internal server, its standard address space taken from :func:`standard_nodes`."""

    def __init__(self, folder: Path | None) -> None:
        super().__init__()
        self._folder = folder

    async def load_standard_address_space(self, shelf_file: Path | None = None) -> None:
        self.aspace._nodes = standard_nodes(self._folder)


async def new_server(folder: Path | None = None) -> Server:
    """An asyncua server, initialised (``Server().init()``) with the kept standard address space."""
    server = Server(iserver=_KeptSpaceServer(folder))
    await server.init()
    return server
