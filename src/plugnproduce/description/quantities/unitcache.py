"""The unit registry, answered from a compact file in the user's cache folder, pint only for what is new.

Importing pint and building its registry costs about half a second of CPU in every process, far
more than a command that reads a few quantities should pay. What the controller asks of the
registry is small: whether a unit is known, and a value in one unit expressed in another. Each
answer pint gives is kept in a small JSON file in the user's cache folder (``units-*.json``, one
per installed pint), so a later process answers from it without importing pint; pint (with its
own parsed-definitions cache in the user's cache folder) is built only for a unit or a pair of
units no process has asked of before.

The answers are pint's own: for units without an offset pint converts a value by multiplying it
by one factor per pair of units, and that factor is what the file keeps (so the value computed is
the same float); a conversion involving an offset unit (``degC``) always goes to pint.
"""

from __future__ import annotations

import contextlib
import importlib.machinery
import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from plugnproduce import folders
from plugnproduce.digests import sha256
from plugnproduce.errors import PlugNProduceError

if TYPE_CHECKING:
    import pint

FORMAT = 1
"""The layout of the file; a file of another layout is ignored (and rewritten)."""
MAX_ENTRIES = 10_000
"""Units and pairs kept at most; beyond, answers are still given but no longer written."""


class Incompatible(PlugNProduceError, ValueError):
    """Two units of different dimensions (pint's ``DimensionalityError``, remembered)."""


def cache_folder() -> Path:
    """The user's cache folder for plugnproduce, where the taxonomy's closure is cached too."""
    return folders.cache_folder()


class Quantity:
    """A number in a unit, as far as the controller uses one: converted with :meth:`to`, read by ``magnitude``."""

    def __init__(self, table: UnitTable, magnitude: float, unit: str) -> None:
        self._table = table
        self.magnitude = magnitude
        self.unit = unit

    def to(self, unit: str) -> Quantity:
        """The same quantity in ``unit``; pint's errors (unknown unit, other dimension) as pint raises them."""
        return Quantity(self._table, self._table.converted(self.magnitude, self.unit, unit), unit)


class UnitTable:
    """Which units pint knows and the factors between them, read from the cache file and added to as pint answers.

    ``Unit`` and ``Quantity`` mirror the two calls of pint's registry the controller makes."""

    def __init__(self, path: Path | None) -> None:
        self.path = path
        self._units: set[str] = set()
        self._factors: dict[str, float | None] = {}
        self._pint: pint.UnitRegistry[float] | None = None
        if path is not None:
            self._read(path)

    def Unit(self, text: str) -> str:  # noqa: N802 - pint's name for it
        """``text`` if pint reads it as a unit; pint's error if it does not."""
        if text not in self._units:
            self.pint().Unit(text)
            self._units.add(text)
            self._write()
        return text

    def Quantity(self, magnitude: float, unit: str) -> Quantity:  # noqa: N802 - pint's name for it
        """A number in ``unit``."""
        return Quantity(self, magnitude, unit)

    def converted(self, magnitude: float, unit: str, to: str) -> float:
        """``magnitude`` in ``unit`` expressed in ``to``, as pint computes it."""
        key = f"{unit}\t{to}"
        if key not in self._factors:
            return self._ask_pint(magnitude, unit, to, key)
        factor = self._factors[key]
        if factor is None:
            raise Incompatible(f"{unit} cannot be converted to {to}")
        return magnitude * factor

    def _ask_pint(self, magnitude: float, unit: str, to: str, key: str) -> float:
        ureg = self.pint()
        import pint

        try:
            one = ureg.Quantity(1.0, unit)
            target = ureg.Quantity(1.0, to)
            if one._is_multiplicative and target._is_multiplicative:
                factor = float(one.to(to).magnitude)
                self._factors[key] = factor
                self._write()
                return magnitude * factor
        except pint.DimensionalityError:
            self._factors[key] = None
            self._write()
            raise
        return float(ureg.Quantity(magnitude, unit).to(to).magnitude)  # an offset: pint every time

    def pint(self) -> pint.UnitRegistry[float]:
        """pint's registry, built on first need from pint's own cache of its parsed definitions."""
        if self._pint is None:
            import pint

            folder: Any = ":auto:" if self.path is not None else None
            self._pint = pint.UnitRegistry(cache_folder=folder)
        return self._pint

    def _read(self, path: Path) -> None:
        with contextlib.suppress(OSError, ValueError, TypeError, AttributeError):
            doc = json.loads(path.read_text(encoding="utf-8"))
            if doc.get("format") == FORMAT:
                self._units = {u for u in doc["units"] if isinstance(u, str)}
                self._factors = {k: (float(v) if v is not None else None) for k, v in doc["factors"].items()
                                 if isinstance(k, str) and (v is None or isinstance(v, int | float))}

    def _write(self) -> None:
        """The table to its file, whole and at once (a concurrent reader sees the old file or the new one)."""
        if self.path is None or len(self._units) + len(self._factors) > MAX_ENTRIES:
            return
        if self.path.is_file():  # another process may have added answers meanwhile: keep theirs too
            other = UnitTable(self.path)
            self._units |= other._units
            self._factors = {**other._factors, **self._factors}
        text = json.dumps({"format": FORMAT, "units": sorted(self._units), "factors": self._factors},
                          sort_keys=True)
        import tempfile  # only writing the table needs it: reading it back does not

        with contextlib.suppress(OSError):  # a cache that cannot be written only costs time
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=".units-", dir=self.path.parent)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as f:
                    f.write(text)
                os.replace(tmp, self.path)
            except OSError:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)


def table_file(folder: Path | None = None) -> Path | None:
    """The cache file for the installed pint (named by where and when pint was installed); None without pint."""
    spec = importlib.machinery.PathFinder.find_spec("pint")  # not importlib.util's: that would load a lazy pint
    if spec is None or spec.origin is None:
        return None
    stamp = f"{spec.origin}\0{os.stat(spec.origin).st_mtime_ns}"
    return (folder or cache_folder()) / f"units-{sha256(stamp.encode()).hexdigest()[:16]}.json"
