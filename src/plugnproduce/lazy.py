"""Modules loaded on first use, so that ``pnp --help`` does not pay for what a command needs.

The command line names the heavy layers (the service, reasoning, drawing) at its top
level but touches them only inside commands. :func:`lazy_module` gives a stand-in whose
first attribute access imports the module; type checkers see the real module through an
``if TYPE_CHECKING`` import beside it.

The stand-in is not put in ``sys.modules``: the module is imported by the ordinary import
system when it is first used, so a package runs before its submodules and each module runs
once, whichever is imported first (a stand-in in ``sys.modules`` either left a submodule to
run before its package, or ran it twice).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Callable, Mapping
from types import ModuleType

_STAND_INS: dict[str, ModuleType] = {}


class _LazyModule(ModuleType):
    """Stands for a module not imported yet; the first attribute it is asked for imports it."""

    def __getattr__(self, attr: str) -> object:  # only for what the stand-in itself does not have
        # asked of the module every time, not copied: a name the module binds anew later (a patched function,
        # a global it replaces) is seen through the stand-in too
        return getattr(importlib.import_module(self.__name__), attr)


def lazy_module(name: str) -> ModuleType:
    """Return the module *name*, imported on its first attribute access.

    A module that is already imported is returned as it is. A name that cannot be
    found raises :class:`ModuleNotFoundError` at once, not at first use.
    """
    loaded = sys.modules.get(name) or _STAND_INS.get(name)
    if loaded is not None:
        return loaded
    spec = importlib.util.find_spec(name)
    if spec is None:
        raise ModuleNotFoundError(f"no module named {name!r}", name=name)
    stand_in = _STAND_INS[name] = _LazyModule(name)
    return stand_in


def lazy_names(package: str, where: Mapping[str, str]) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__`` (:pep:`562`) for names imported from their modules on first use.

    ``where`` maps each name to the module that defines it (relative to ``package`` when it starts with a dot),
    followed by ``:NAME`` when it has another name there. A name, once imported, is kept in the package.
    """
    namespace = sys.modules[package].__dict__

    def get(name: str) -> object:
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, original = where[name].partition(":")
        value = getattr(importlib.import_module(module, package), original or name)
        namespace[name] = value
        return value

    def names() -> list[str]:
        return sorted({*namespace, *where})

    return get, names
