"""SCXML in and out: the project's one reader, one writer and the W3C schema check."""

from __future__ import annotations
