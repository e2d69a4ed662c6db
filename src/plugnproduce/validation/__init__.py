"""Validation of descriptions: parsing, W3C SCXML schema, SHACL shapes and structure.

:func:`validate_paths` reads files and folders and returns a :class:`Report`; a
problem is a result with a place, never an exception. Only unreadable or hostile
input is reported as such (the CLI exits 2 for it).
"""

from __future__ import annotations

from plugnproduce.validation.findings import Finding, Report
from plugnproduce.validation.validate import validate_paths, validate_tasks

__all__ = ["Finding", "Report", "validate_paths", "validate_tasks"]
