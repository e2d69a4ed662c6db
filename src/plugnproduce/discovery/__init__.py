"""Discovery: the live cell, as devices plug in and unplug (paper sections 2 and 7)."""

from __future__ import annotations

from plugnproduce.discovery.live import CellChange, LiveCell

__all__ = ["CellChange", "LiveCell"]
