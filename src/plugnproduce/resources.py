"""Where the project's data files are: shipped in the wheel, or in the checkout.

``ontology/``, ``rules/`` and ``descriptions/`` live at the top of the repository and
are mapped into the wheel as ``plugnproduce/data/<name>``. An editable install has
no such copy, so the checkout's folder is used instead.
"""

from __future__ import annotations

from pathlib import Path

DATA_FOLDERS = ("ontology", "rules", "descriptions")
PACKAGE = Path(__file__).parent
"""The package's folder: where ``importlib.resources`` finds its files when installed as files (the package reads
its data as files, so it is; naming the folder directly saves every command importing ``importlib.resources`` and
the zip support it brings)."""


def data_path(name: str) -> Path:
    """The folder of shipped data called ``name`` (one of :data:`DATA_FOLDERS`)."""
    if name not in DATA_FOLDERS:
        raise ValueError(f"unknown data folder {name!r}; expected one of {DATA_FOLDERS}")
    shipped = PACKAGE / "data" / name
    if shipped.is_dir():
        return shipped
    checkout = Path(__file__).resolve().parents[2] / name
    if checkout.is_dir():
        return checkout
    raise FileNotFoundError(f"data folder {name!r} is neither in the package nor in a checkout")


def ontology_path() -> Path:
    """The ontology folder (OWL TBox and SHACL shapes)."""
    return data_path("ontology")


def rules_path() -> Path:
    """The folder of ASP encodings."""
    return data_path("rules")


def descriptions_path() -> Path:
    """The folder of built-in descriptions: devices, processes, tasks, cells."""
    return data_path("descriptions")


def package_file(*parts: str) -> Path:
    """A data file that lives inside the package itself (e.g. the W3C SCXML schema)."""
    return PACKAGE.joinpath(*parts)
