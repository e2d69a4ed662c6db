"""Device descriptions as read, kept in the user's cache folder so that a command over unchanged files reads them back.

A cell's devices are read from Turtle and their device state charts at every command, though they rarely
change between two commands; reading Turtle costs rdflib, whose import alone costs more than the answer. A read
device is kept as a pickle named by the digest of what it was read from and with: the package's code (as the
kept knowledge is named, :func:`~plugnproduce.knowledge.cache.code_digest`), the taxonomy it was reasoned with
(by the content of its TBox), the description's path and its content. Its device state chart's content is
checked when the pickle is read. An edit of either names another file, or fails the check; a file that cannot be
read or unpickled is read again, and a cache folder that cannot be written only costs the next command a read.
The folder is the user's own, so the pickle is as trusted as the user's files.
"""

from __future__ import annotations

import contextlib
import pickle
import weakref
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from plugnproduce import folders
from plugnproduce.description.model import DeviceDescription
from plugnproduce.digests import sha256
from plugnproduce.knowledge.cache import cache_folder, code_digest

if TYPE_CHECKING:
    from plugnproduce.ontology.taxonomy import Taxonomy

FORMAT = 1
"""The layout of what is kept; another layout is another file name."""
KEEP = 256
"""Device files kept in the cache folder; older ones are removed when a new one is written."""


def _read(path: Path) -> bytes | None:
    try:
        return path.read_bytes()
    except OSError:
        return None


def _chart_digest(device: DeviceDescription) -> str | None:
    data = _read(Path(device.chart_file))
    return None if data is None else sha256(data).hexdigest()


def _load_device(path: Path, taxonomy: Taxonomy) -> DeviceDescription:
    from plugnproduce.description.loader import load_device  # reads RDF: only when nothing is kept

    return load_device(path, taxonomy)


def cached_device(path: str | Path, taxonomy: Taxonomy, folder: Path | None = None,
                  read: Callable[[Path, Taxonomy], DeviceDescription] | None = None) -> DeviceDescription:
    """The device description at ``path`` reasoned with ``taxonomy``: read back from the cache folder when kept
    there for the same code, taxonomy and content (of the description and its chart), else read (by ``read``,
    default :func:`~plugnproduce.description.loader.load_device`), then kept. A description that cannot be read
    or is bad input is read as without a cache, so that what is wrong is said the same way."""
    p = Path(path)
    read = read or _load_device
    data = _read(p)
    if data is None:
        return read(p, taxonomy)
    h = sha256(f"{FORMAT}\0{code_digest()}\0{taxonomy.digest}\0{p}\0".encode())
    h.update(data)
    kept = (folder or cache_folder()) / f"device-{h.hexdigest()[:32]}.pickle"
    with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError,
                             ValueError, IndexError):
        device, chart = pickle.loads(kept.read_bytes())  # noqa: S301 - the user's own cache folder, by content
        if isinstance(device, DeviceDescription) and chart is not None and chart == _chart_digest(device):
            return _served(device, f"{h.hexdigest()}\0{chart}", kept.parent)
    device = read(p, taxonomy)
    chart = _chart_digest(device)
    with contextlib.suppress(OSError, pickle.PicklingError, TypeError, AttributeError):
        folders.keep_newest(kept, pickle.dumps((device, chart), protocol=pickle.HIGHEST_PROTOCOL), KEEP)
    return device if chart is None else _served(device, f"{h.hexdigest()}\0{chart}", kept.parent)


_SERVED: dict[int, tuple[weakref.ref[DeviceDescription], str, Path]] = {}
"""The devices :func:`cached_device` gave in this process and still alive, by identity: each with the digest of
what it was read from (the code, taxonomy, description and chart) and its cache folder, for what is made of it to
be kept (:func:`kept_facts`). By identity, not equality: a copy made by :func:`dataclasses.replace` is not among
them. Not held: a device's entry goes when the device does (before its id can name another object), so a
long-running process that reads devices again and again keeps none of them."""


def _served(device: DeviceDescription, key: str, folder: Path) -> DeviceDescription:
    at, served = id(device), _SERVED  # the dict itself, not the module's name for it: gone at interpreter exit
    served[at] = (weakref.ref(device, lambda _: served.pop(at, None)), key, folder)
    return device


def kept_facts(device: DeviceDescription, knowledge: str | None, make: Callable[[], str]) -> str:
    """``make()``: the ASP facts of ``device`` with the knowledge whose key (:attr:`~.libraries.Knowledge.key`) is
    ``knowledge``, read back from the cache folder when kept there for the same device (as :func:`cached_device`
    read it) and knowledge, else made, then kept. Made, and not kept, for a device :func:`cached_device` did not
    give or knowledge without a key: what it was made from is not known by name."""
    served = _SERVED.get(id(device))
    if served is None or served[0]() is not device or knowledge is None:
        return make()
    _, key, folder = served
    name = sha256(f"{FORMAT}\0{key}\0{knowledge}".encode()).hexdigest()[:32]
    return folders.made_once(folder / f"facts-{name}.pickle", make, KEEP)


def device_reader(taxonomy: Taxonomy, folder: Path | None = None) -> Callable[[Path], DeviceDescription]:
    """:func:`cached_device` with ``taxonomy``, as a cell's or a catalogue's reader of device files."""
    return lambda path: cached_device(path, taxonomy, folder)


def kept_devices(folder: Path | None = None) -> Iterable[Path]:
    """The device files kept in the cache folder."""
    return sorted((folder or cache_folder()).glob("device-*.pickle"))
