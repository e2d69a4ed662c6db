"""Python's cyclic garbage collector paused while many long-lived objects are made at once.

Each automatic collection walks every tracked object; while a large chart is compiled, a long task's repairs are
made, or OPC UA's standard address space is read, a collection finds nothing to free and only walks what was made.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def paused() -> Iterator[None]:
    """No automatic collection inside the block (it was on: it is on again after)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
