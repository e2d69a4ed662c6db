"""Every name the service and the controller give the faces is there: the ones imported on first use too (a name
whose module moved would otherwise fail only when a command first uses it)."""

from __future__ import annotations

import importlib

import pytest


@pytest.mark.parametrize("package", ["plugnproduce.service", "plugnproduce.controller"])
def test_every_name_given_to_the_faces_resolves(package: str) -> None:
    module = importlib.import_module(package)
    missing = []
    for name in module.__all__:
        try:
            getattr(module, name)
        except (AttributeError, ImportError) as exc:
            missing.append(f"{name}: {exc}")
    assert missing == []


def test_a_name_neither_gives_is_an_attribute_error() -> None:
    from plugnproduce import controller, service

    for module in (service, controller):
        with pytest.raises(AttributeError, match="no attribute 'LiveCel'"):
            module.LiveCel  # noqa: B018
