"""Modules loaded on first use, so that ``pnp --help`` does not pay for what a command needs.

The command line names the heavy layers (the service, reasoning, drawing) at its top
level but touches them only inside commands. :func:`lazy_module` gives such a module
object whose code runs on the first attribute access; type checkers see the real
module through an ``if TYPE_CHECKING`` import beside it.
"""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType

_WHERE = frozenset({"__name__", "__spec__", "__path__", "__loader__", "__package__", "__file__"})
"""What the import system reads of a parent package to import a submodule."""


class _LazyModule(importlib.util._LazyModule):  # type: ignore[name-defined,misc]
    """A module whose code runs on first use; reading where it is (its ``__path__``) is no use.

    Importing a submodule of a package reads the package's ``__path__``. Were that to run the
    package's code, which imports the same submodule, the import would then run the submodule a
    second time, and two copies of it (of its registries, its classes) would exist.
    """

    def __getattribute__(self, attr: str) -> object:
        if attr in _WHERE:
            return ModuleType.__getattribute__(self, attr)
        return super().__getattribute__(attr)


def lazy_module(name: str) -> ModuleType:
    """Return the module *name*, executed on its first attribute access.

    A module that is already imported is returned as it is. A name that cannot be
    found raises :class:`ModuleNotFoundError` at once, not at first use.
    """
    loaded = sys.modules.get(name)
    if loaded is not None:
        return loaded
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        raise ModuleNotFoundError(f"no module named {name!r}", name=name)
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    loader.exec_module(module)
    module.__class__ = _LazyModule
    parent, _, child = name.rpartition(".")
    if parent:
        setattr(sys.modules[parent], child, module)
    return module
